/* Tests of the GLSL traversal and the renderer on the Vulkan device (test_gpu.c). */
TEST(gpu, traversal_random)
TEST(gpu, traversal_sphere)
TEST(gpu, traversal_shallow)
TEST(gpu, traversal_edges)
TEST(gpu, traversal_deep)
TEST(gpu, texture_wrap)
