/* Tests of the gpu module: TEST(suite, name) lines, defined in test_gpu.c. */
