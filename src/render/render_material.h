/* render_material.h: what the renderer derives from a scene's materials: the kernel
 * features each needs, and BRDF-model overrides (--brdf, extras.gonio). */
#ifndef GONIO_RENDER_MATERIAL_H
#define GONIO_RENDER_MATERIAL_H

#include <stdbool.h>
#include <stdint.h>

#include "scene.h"

/* The GN_FEAT_* that material m can need in the path kernel (renderer_create ORs them over
 * the scene's materials to specialise the kernel). */
GnFeatures material_features(const GnMaterial *m);

/* Applies BRDF-model overrides to the scene's materials (GnMaterial.brdf, brdf_params and
 * the model's colour): each material's extras {"gonio": {"brdf": NAME, PARAM: VALUE...}}
 * and, when brdf is not NULL, "NAME[:PARAM=VALUE...]" for every material (winning over
 * extras). False with an error naming the scene and material on a bad name or value. */
bool render_material_overrides(scene *sc, const char *brdf);

#endif
