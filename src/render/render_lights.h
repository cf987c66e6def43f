/* render_lights.h: the lights of a render. The local modes' lights (GN_BIND_LIGHTS: the
 * scene's punctual lights, or stand-ins for its emissive meshes), and the path tracer's light
 * table (GN_BIND_EMITTERS: each emissive triangle and punctual light with a selection weight
 * proportional to its power, then the environment) with the environment map and the CDFs
 * that importance sample it (GN_BIND_ENV). */
#ifndef GONIO_RENDER_LIGHTS_H
#define GONIO_RENDER_LIGHTS_H

#include <stdbool.h>
#include <stdint.h>

#include "gpu.h"
#include "image.h"
#include "render_geometry.h"
#include "scene.h"

typedef struct render_lights {
    uint32_t num_lights;    /* the local modes' lights */
    /* the path tracer's light table: its triangles (num_area of them), then its punctual
     * lights; a slot more for the environment */
    GnEmitter *table;
    double *weight;         /* each entry's selection weight (flux / pi) */
    uint32_t *instance;     /* with instances: each entry's instance (GN_INVALID: a light) */
    uint32_t cap;           /* the table's room (with instances, where the instances follow) */
    uint32_t num_emitters, num_area;
    const image *env_source; /* the map now in `env` */
    double env_weight;      /* its selection weight */
    gpu_buffer lights, emitters, env;
    uint32_t replaced;      /* buffers made anew so far: kernels bound to the old ones rebind */
} render_lights;

/* The lights of sc, whose trees are geo, uploaded. */
void render_lights_create(render_lights *l, gpu *g, const scene *sc, const render_geometry *geo);
/* sc is the scene of l at another time (the same geometry, instances moved, other lights):
 * the lights and the light table made again; the environment's weight is recomputed at the
 * next render_lights_path. */
void render_lights_update(render_lights *l, gpu *g, const scene *sc, const render_geometry *geo);
void render_lights_destroy(render_lights *l, gpu *g); /* accepts a zeroed struct */

/* The light table's triangle entries at most: each instance's emissive triangles, or the
 * scene's slots (render_scene_fits). */
uint64_t render_lights_room(const scene *sc, const render_geometry *geo);

/* The path tracer's lights for a render: the environment (env_map, a lat-long map, uploaded
 * when it is new; else the constant env_color) added to the table, which is normalised and
 * uploaded; frame's emitter and environment fields set, *env_weight the environment's
 * selection weight (0: none). False (with an error) on a bad map. */
bool render_lights_path(render_lights *l, gpu *g, const scene *sc, const render_geometry *geo, const image *env_map,
                        const float env_color[3], GnFrame *frame, double *env_weight);

#endif
