/* Tests of the MikkTSpace tangent generator (src/tangent.c), defined in test_tangent.c. */
TEST(tangent, plane)
TEST(tangent, mirror_seam)
TEST(tangent, cylinder)
TEST(tangent, degenerate)
