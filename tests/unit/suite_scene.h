/* Tests of the scene module: TEST(suite, name) lines, defined in test_scene.c. */
