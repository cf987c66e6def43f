/* fuzz_scene.c: libFuzzer target over scene_load (glTF JSON and GLB, detected by content)
 * and the trees a loaded scene gets (render_geometry_build: with instances, two levels).
 * Any input must give a scene or false with an error, never a crash, a sanitizer report,
 * a leak or a hang. Seeds: tests/fuzz/run.sh. */
#include "fuzz_common.h"
#include "render_geometry.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scene sc;
    util_set_quiet(true);
    util_set_silent(true); /* the loader's warnings and errors: most of the time otherwise */
    /* Half the inputs posed at a time of their animations: joints, morph weights. */
    scene_animation_time(size % 2 ? 0.37 : -1);
    if (scene_load(&sc, fuzz_write_input("in.gltf", data, size))) {
        render_geometry g;
        if (render_geometry_build(&g, &sc))
            render_geometry_destroy(&g);
        scene_destroy(&sc);
    }
    return 0;
}
