/* Tests of flat, Gouraud and per-pixel Phong shading on the Vulkan device (test_shading.c). */
TEST(shading, gouraud_triangle)
TEST(shading, flat_constant)
TEST(shading, phong_sphere)
TEST(shading, highlight_missed)
