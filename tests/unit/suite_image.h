/* Tests of the image module: TEST(suite, name) lines, defined in test_image.c. */
