/* environment.h: the light from infinitely far away: lat-long maps (OpenEXR or Radiance
 * .hdr), and gonio's default "studio" environment for scenes that bring no light of their
 * own. The commands take it as --env (a constant radiance, a map or the studio), its rotation
 * and intensity (src/cli/options.c: the options and env_setup, the rule below).
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
#include "scene.h"

/* Whether the scene brings light of its own: a punctual light, or an emissive material
 * brighter than 1 (core glTF's emissive range is a glow, not a light source). */
bool env_scene_has_light(const scene *sc);

/* The studio environment: a lat-long map (R, G, B) of a soft grey room, brighter above, a
 * large soft key light high at the front left (left out without with_key: the local modes take
 * it as environment_studio_key's light) and a weaker fill at the right. */
void environment_studio(image *out, bool with_key);
/* The studio's key light as a directional light (the local modes' light under the studio). */
void environment_studio_key(GnLight *out);

/* Reads a Radiance RGBE (.hdr) file into R, G, B float planes (stb_image). */
bool environment_read_hdr(image *out, const char *path);

/* Mean radiance over the sphere of a lat-long map (solid-angle weighted). */
void environment_mean(const image *map, float out[3]);

#endif
