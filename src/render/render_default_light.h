/* render_default_light.h: the light a render gets (docs/path-tracing.md, "Light when the
 * scene has none"), one rule for every command that renders a file (render and batch,
 * preview, compare):
 *   - --env given: that environment (a constant, a map, or gonio's studio beside the file's
 *     lights), nothing else decides;
 *   - else the file's own image-based light (EXT_lights_image_based) when it has one;
 *   - else a file without lights: gonio's studio environment, announced;
 *   - a file whose own lights leave the view dark (a probe render: most of the model unlit):
 *     the studio added to them, announced;
 *   - where the studio lights the view by default and the camera is inside a closed model
 *     that keeps it out: a headlight (a point light at the camera) in its place, announced.
 * The local modes see an environment as its mean radiance added to the ambient light (unless
 * --ambient) and the studio as its key light among the scene's lights, so the rule depends on
 * the render's mode (path or local). */
#ifndef GONIO_RENDER_DEFAULT_LIGHT_H
#define GONIO_RENDER_DEFAULT_LIGHT_H

#include <stdbool.h>

#include "image.h"
#include "render.h"
#include "scene.h"

/* What the user asked of the light (--env, --env-rotate, --env-intensity); all zero:
 * nothing, the rule decides. */
typedef struct render_light_request {
    bool given;              /* --env was on the command line */
    const char *path;        /* a map (.exr or .hdr), else NULL: the constant `color` */
    bool studio;             /* --env studio: gonio's studio, whatever lights the scene has */
    float color[3];
    float rotation;          /* degrees about +Y, right-handed (--env-rotate) */
    float intensity;         /* scale of the radiance (--env-intensity); 0 means 1 */
} render_light_request;

/* The light the rule chose, which a render's settings point into (s->env_map). */
typedef struct render_lighting {
    image map;               /* the environment map, scaled by the intensity (empty: none) */
    bool studio;             /* gonio's studio lights the view */
    bool headlight;          /* a headlight replaced it */
    bool ambient_given;      /* --ambient was given: the local modes' ambient stays */
    const char *label;       /* for headers (gonio:environment): "studio", "headlight", the
                              * map's path, "constant", "none" */
} render_lighting;

/* The rule's first step, before the renderer of sc exists: s's environment (env, env_map,
 * env_rotation; a map read into l->map) from the request and the scene, the local modes' key
 * light added to sc's lights and their ambient light set (s->mode says which kernel). False
 * (with an error naming the file) on a bad map. Announcements on stderr unless quiet. */
bool render_light_begin(const render_light_request *e, scene *sc, bool quiet, render_settings *s,
                        render_lighting *l);
/* Its second step, with r, the renderer of sc (made after render_light_begin): the probe
 * render of s's view and the headlight's test, which may add lights to sc; r is then made
 * again (on the same device). False when that fails. */
bool render_light_finish(const render_light_request *e, scene *sc, renderer *r, render_settings *s, bool quiet,
                         render_lighting *l);
/* Frees l's map and empties l; s->env_map must not point at it any more. */
void render_lighting_destroy(render_lighting *l);

#endif
