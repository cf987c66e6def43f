/* environment.h: the light from infinitely far away, as the commands take it: --env (a
 * constant radiance, an OpenEXR or Radiance .hdr lat-long map), its rotation and intensity,
 * and gonio's default "studio" environment for scenes that bring no light of their own.
 *
 * A scene with no punctual light, no emitter brighter than 1 and no --env is lit by the studio
 * (environment_studio), announced on stderr; `--env 0` renders such a scene black on purpose.
 * The path tracer samples the map (glsl/kernels/path.comp); the local modes take its mean radiance as
 * the Phong model's ambient light, and under the studio also its key light as a directional
 * light, so an unlit scene is lit and shaded in every mode. */
#ifndef GONIO_ENVIRONMENT_H
#define GONIO_ENVIRONMENT_H

#include <stdbool.h>

#include "image.h"
#include "render.h"
#include "scene.h"

typedef struct env_option {
    bool given;              /* --env was on the command line */
    const char *path;        /* a map (.exr or .hdr), else NULL: the constant `color` */
    bool studio;             /* --env studio: gonio's studio, whatever lights the scene has */
    float color[3];
    float rotation;          /* degrees about +Y, right-handed (--env-rotate) */
    float intensity;         /* scale of the radiance (--env-intensity); 0 means 1 */
} env_option;

/* The environment options of render and preview (cli.h: a cli_option list for a table). */
#define ENV_OPTIONS(env)                                                                       \
    {"--env", "R,G,B | V",                                                                     \
     "constant environment radiance; 0: black (default: the scene's own\n"                     \
     "lights, or gonio's studio environment when it has none)",                                \
     CLI_CALL, CLI_AS(env_option, env), 0, 0, NULL, env_take_option},                                            \
    {NULL, NULL,                                                                               \
     "  --env FILE          a lat-long HDR environment map, OpenEXR (.exr) or Radiance (.hdr),\n" \
     "                      +Y up; importance sampled by the path tracer, its mean radiance is\n" \
     "                      the local modes' ambient light\n"                                  \
     "  --env studio        gonio's studio environment besides the scene's own lights (as model\n" \
     "                      viewers light a scene that has only punctual lights)\n",            \
     CLI_TEXT, NULL, 0, 0, NULL, NULL},                                                        \
    {"--env-rotate", "DEG", "turn the environment about +Y (right-handed, default 0)",        \
     CLI_CALL, CLI_AS(env_option, env), 0, 0, NULL, env_take_option},                                            \
    {"--env-intensity", "X", "scale the environment's radiance (default 1)",                  \
     CLI_CALL, CLI_AS(env_option, env), 0, 0, NULL, env_take_option}

/* Takes opt (and its value) when it is an environment option: 1 taken, 0 not one, 2 after a
 * usage error printed for command cmd. */
int env_parse_option(env_option *e, const char *cmd, const char *opt, const char *val);
/* env_parse_option as a cli_option's call (dest: the env_option). */
bool env_take_option(const char *cmd, const char *opt, const char *val, void *dest);

/* Whether the scene brings light of its own: a punctual light, or an emissive material
 * brighter than 1 (core glTF's emissive range is a glow, not a light source). */
bool env_scene_has_light(const scene *sc);

/* Sets s's environment (env, env_map, env_rotation) from e for scene sc, reading a map into
 * *map (which the caller destroys), or the studio when e is not given and the scene has no
 * light, announced on stderr unless quiet; *studio tells which. For a local mode (s->mode)
 * the environment's mean radiance becomes the ambient light (unless s->ambient_set) and the
 * studio's key light is added to sc's lights. False with an error naming the file on a bad
 * map. */
bool env_setup(const env_option *e, scene *sc, bool quiet, image *map, render_settings *s, bool *studio);

/* The studio environment: a lat-long map (R, G, B) of a soft grey room, brighter above, a
 * large soft key light high at the front left and a weaker fill at the right. */
void environment_studio(image *out);
/* The studio's key light as a directional light (the local modes' light under the studio). */
void environment_studio_key(GnLight *out);

/* Reads a Radiance RGBE (.hdr) file into R, G, B float planes (stb_image). */
bool environment_read_hdr(image *out, const char *path);

/* Mean radiance over the sphere of a lat-long map (solid-angle weighted). */
void environment_mean(const image *map, float out[3]);

#endif
