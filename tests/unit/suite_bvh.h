/* Tests of the bvh module: TEST(suite, name) lines, defined in test_bvh.c. */
