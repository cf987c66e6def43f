/* Tests of normal mapping on third-party models (glsl/scene.glsl: surface_at), in test_normals.c. */
TEST(normals, generated_tangents)
TEST(normals, tangent_test_layout)
TEST(normals, strong_scale)
