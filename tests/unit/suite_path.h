/* Tests of the path tracer (glsl/path.comp), defined in test_path.c. */
TEST(path, furnace)
TEST(path, env_map)
TEST(path, estimators)
TEST(path, convergence)
TEST(path, cornell_reference)
TEST(path, determinism)
TEST(path, batching)
TEST(path, merge)
