/* Tests of glTF alphaMode MASK and BLEND (glsl/bvh.glsl: trace_visible), in test_alpha.c. */
TEST(alpha, camera_rays)
TEST(alpha, shadow_rays)
