/* suites.h: every unit test, one line each: TEST(suite, name). Add yours to your suite. */
#include "suite_bvh.h"
#include "suite_scene.h"
#include "suite_image.h"
#include "suite_gpu.h"
#include "suite_gen.h"
#include "suite_brdf.h"
#include "suite_shading.h"
#include "suite_path.h"
