/* render_default_light.c: the light a render gets (render_default_light.h). */
#include "render_default_light.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "environment.h"
#include "util.h"
#include "vec.h"

/* The studio in map; the local modes see it as its key light (added to sc's lights) plus
 * the mean of the rest. */
static void studio_setup(const render_light_request *e, scene *sc, bool local, image *map)
{
    if (local) {
        GnLight key;
        environment_studio_key(&key);
        /* --env-rotate turns the key with the map (R_Y, as path.comp turns the map). */
        float ca = cosf(e->rotation * (float)(M_PI / 180)), sa = sinf(e->rotation * (float)(M_PI / 180));
        vec3 d = key.direction;
        key.direction = (vec3){ca * d.x + sa * d.z, d.y, -sa * d.x + ca * d.z};
        sc->lights = util_realloc(sc->lights, (sc->num_lights + 1) * sizeof *sc->lights);
        sc->lights[sc->num_lights++] = key;
        environment_studio(map, false);
    } else {
        environment_studio(map, true);
    }
}

/* map, scaled by --env-intensity, as the render's environment; mean: its mean radiance. */
static void env_use_map(image *map, float scale, float mean[3], render_settings *s)
{
    if (scale != 1)
        for (int c = 0; c < map->num_channels; c++)
            for (size_t i = 0; i < (size_t)map->width * map->height; i++)
                map->planes[c][i] *= scale;
    environment_mean(map, mean);
    s->env_map = map;
}

bool render_light_begin(const render_light_request *e, scene *sc, bool quiet, render_settings *s,
                        render_lighting *l)
{
    float scale = e->intensity > 0 ? e->intensity : 1, mean[3] = {0, 0, 0};
    bool local = s->mode != GN_MODE_PATH;
    image *map = &l->map;
    memset(l, 0, sizeof *l);
    l->ambient_given = s->ambient_set;
    l->label = e->path ? e->path : e->given && !e->studio ? "constant" : "none";
    s->env_map = NULL;
    s->env_rotation = e->rotation;
    if (e->given && !e->path && !e->studio) {
        for (int k = 0; k < 3; k++)
            mean[k] = s->env[k] = e->color[k] * scale;
    } else if (!e->given && sc->environment.num_channels) {
        /* The file's own image-based light (EXT_lights_image_based): its environment. */
        const image *src = &sc->environment;
        static const char *const rgb[3] = {"R", "G", "B"};
        image_create(map, src->width, src->height, 3, rgb);
        for (int c = 0; c < 3; c++)
            memcpy(map->planes[c], src->planes[c], sizeof(float) * (size_t)src->width * src->height);
        if (!quiet)
            util_info("%s: lit by its image-based light (%s; --env replaces it)", sc->path, sc->environment_what);
        env_use_map(map, scale, mean, s);
    } else if (e->given || !env_scene_has_light(sc)) {
        if (e->path) {
            bool ok = util_has_suffix(e->path, ".hdr") ? environment_read_hdr(map, e->path) : image_read_exr(map, e->path);
            if (!ok)
                return false;
        } else {
            l->studio = true;
            if (!quiet && !e->studio)
                util_info("%s has no lights: lit by gonio's studio environment (--env 0 for black)", sc->path);
            studio_setup(e, sc, local, map);
        }
        env_use_map(map, scale, mean, s);
    }
    /* The local modes: the environment is the Phong model's ambient light, unless --ambient
     * (the path tracer does not read it). */
    if (!s->ambient_set) {
        for (int k = 0; k < 3; k++)
            s->ambient[k] = sc->ambient[k] + mean[k];
        s->ambient_set = true;
    }
    if (l->studio)
        l->label = "studio";
    return true;
}

/* ---- a view the file's own light leaves dark ---------------------------------------------
 * The rule (docs/path-tracing.md, "Light when the scene has none"): a probe render of the
 * view with the file's lights alone (path tracing, ENV_PROBE_SIZE pixels on the longer side,
 * ENV_PROBE_SPP samples); of the pixels that see the model, the fraction brighter than
 * ENV_PROBE_LEVEL (1/40 of what a white surface reflects under the studio) is the lit
 * fraction; below ENV_PROBE_LIT the view is dark and the studio is added to the file's lights. */
#define ENV_PROBE_SIZE 64
#define ENV_PROBE_SPP 8
#define ENV_PROBE_LEVEL 0.02f
#define ENV_PROBE_LIT 0.6f

static bool env_probe_applies(const render_light_request *e, const scene *sc)
{
    return !e->given && !sc->environment.num_channels && env_scene_has_light(sc);
}

static float env_probe_lit_fraction(renderer *r, const render_settings *s, bool with_env)
{
    render_settings p = *s;
    p.mode = GN_MODE_PATH;
    if (s->width >= s->height) {
        p.width = ENV_PROBE_SIZE;
        p.height = (int)fmaxf(1, roundf((float)ENV_PROBE_SIZE * (float)s->height / (float)s->width));
    } else {
        p.height = ENV_PROBE_SIZE;
        p.width = (int)fmaxf(1, roundf((float)ENV_PROBE_SIZE * (float)s->width / (float)s->height));
    }
    p.spp = ENV_PROBE_SPP;
    p.time_limit = 0;
    p.aov = 0;
    p.progress = NULL;
    p.stop = NULL;
    if (!with_env) {
        p.env_map = NULL;
        p.env[0] = p.env[1] = p.env[2] = 0;
    }
    p.strategy = 0;
    p.crop_x0 = p.crop_y0 = p.crop_x1 = p.crop_y1 = 0;
    p.resume = NULL;
    p.resume_spp = 0;
    image img = {0};
    render_stats st;
    if (!renderer_render(r, &p, &img, &st))
        return -1;
    int ch[4] = {image_channel(&img, "R"), image_channel(&img, "G"), image_channel(&img, "B"), image_channel(&img, "A")};
    long seen = 0, lit = 0;
    for (size_t i = 0; ch[0] >= 0 && ch[1] >= 0 && ch[2] >= 0 && ch[3] >= 0 && i < (size_t)img.width * img.height; i++) {
        if (!(img.planes[ch[3]][i] > 0.5f))
            continue;
        const float rgb[3] = {img.planes[ch[0]][i], img.planes[ch[1]][i], img.planes[ch[2]][i]};
        double lum = vec_luminance(rgb);
        seen++;
        lit += lum > ENV_PROBE_LEVEL;
    }
    image_destroy(&img);
    return seen ? (float)lit / (float)seen : -1;
}

static bool env_probe_is_dark(float lit)
{
    return lit >= 0 && lit < ENV_PROBE_LIT;
}

static void env_add_studio(const render_light_request *e, scene *sc, bool quiet, float lit, render_lighting *l,
                           render_settings *s)
{
    float scale = e->intensity > 0 ? e->intensity : 1, mean[3];
    if (!quiet || util_strict())
        util_fallback("%s: its own light leaves the view dark (%.0f %% of the model brighter than %g, under %.0f %%): "
                      "added gonio's studio environment (--env 0 for the file's light alone)",
                      sc->path, 100 * lit, ENV_PROBE_LEVEL, 100 * ENV_PROBE_LIT);
    image_destroy(&l->map);
    studio_setup(e, sc, s->mode != GN_MODE_PATH, &l->map);
    env_use_map(&l->map, scale, mean, s);
    if (!l->ambient_given)
        for (int k = 0; k < 3; k++)
            s->ambient[k] += mean[k];
    l->studio = true;
    l->label = "studio";
}

/* ---- a camera inside a closed model ------------------------------------------------------
 * The rule's second step (docs/path-tracing.md, "Light when the scene has none"): where the
 * studio lights the view by default, a camera inside a closed model (a sky dome around a
 * city, a room without a window) keeps it out. Of ENV_ENCLOSED_RAYS rays from the camera,
 * spread evenly over the sphere (a spherical Fibonacci set) and traced on the host through
 * the render's own trees, at least ENV_ENCLOSED meet the scene: the camera is enclosed, and
 * the probe is rendered again with the studio. Still dark, a headlight replaces the studio:
 * a point light at the camera, which lights everything the camera sees (nothing stands
 * between them), as bright as the studio makes a white surface (luminance 0.8, 40
 * ENV_PROBE_LEVEL) at the median distance of what the view's rays (ENV_VIEW_RAYS^2 through
 * the image) meet. The studio goes: what it reaches through an opening or glass is little
 * (the view stayed dark), and kept it would take most light samples (the image noisy). Both
 * kinds of ray start at the camera's znear, as its own rays do (a cutaway camera sees
 * through what its near plane clips). */
#define ENV_ENCLOSED_RAYS 1024
#define ENV_ENCLOSED 0.99f
#define ENV_VIEW_RAYS 32
#define ENV_HEADLIGHT_WHITE (40 * ENV_PROBE_LEVEL)

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static float trace_distance(const renderer *r, const float org[3], const float dir[3], float tmin)
{
    bvh_hit h = r->geo.two_levels ? bvh_top_intersect(&r->geo.top, org, dir, tmin, INFINITY, NULL)
                                  : bvh_intersect(&r->geo.world, org, dir, tmin, INFINITY, NULL);
    return h.tri == GN_INVALID ? -1 : h.t;
}

static bool env_add_headlight(renderer *r, scene *sc, render_settings *s, bool quiet)
{
    GnCamera cam;
    if (r->failed || !renderer_camera(r, s, &cam))
        return false;
    const float org[3] = {cam.position.x, cam.position.y, cam.position.z};
    int hits = 0;
    const double golden = M_PI * (3 - sqrt(5.0));
    for (int i = 0; i < ENV_ENCLOSED_RAYS; i++) {
        float z = 1 - (2 * i + 1) / (float)ENV_ENCLOSED_RAYS, rho = sqrtf(fmaxf(0, 1 - z * z));
        float dir[3] = {rho * (float)cos(golden * i), rho * (float)sin(golden * i), z};
        hits += trace_distance(r, org, dir, cam.znear) >= 0;
    }
    float enclosed = (float)hits / ENV_ENCLOSED_RAYS;
    if (enclosed < ENV_ENCLOSED)
        return false;
    float seen[ENV_VIEW_RAYS * ENV_VIEW_RAYS];
    int num_seen = 0;
    for (int y = 0; y < ENV_VIEW_RAYS; y++)
        for (int x = 0; x < ENV_VIEW_RAYS; x++) { /* GnCamera's mapping (glsl/lib/shared.h) */
            float sx = 2 * (x + 0.5f) / ENV_VIEW_RAYS - 1, sy = 1 - 2 * (y + 0.5f) / ENV_VIEW_RAYS;
            const float right[3] = {cam.right.x, cam.right.y, cam.right.z}, up[3] = {cam.up.x, cam.up.y, cam.up.z};
            float ro[3] = {org[0], org[1], org[2]}, rd[3] = {cam.forward.x, cam.forward.y, cam.forward.z};
            float h = cam.ortho_half_height > 0 ? cam.ortho_half_height : cam.tan_half_fovy;
            for (int k = 0; k < 3; k++) { /* orthographic: the origin moves; perspective: the direction */
                float off = h * (sx * cam.aspect * right[k] + sy * up[k]);
                if (cam.ortho_half_height > 0)
                    ro[k] += off;
                else
                    rd[k] += off;
            }
            vec_normalize(rd);
            float t = trace_distance(r, ro, rd, cam.znear);
            if (t >= 0)
                seen[num_seen++] = t;
        }
    if (num_seen == 0)
        return false;
    float lit = env_probe_lit_fraction(r, s, true);
    if (!env_probe_is_dark(lit))
        return false;
    qsort(seen, (size_t)num_seen, sizeof *seen, cmp_float);
    float d = seen[num_seen / 2];
    /* A white Lambertian surface facing the light at distance d: radiance I / d^2 / pi in the
     * path tracer; the local modes' Phong diffuse term has no 1 / pi (environment_studio_key). */
    float intensity = ENV_HEADLIGHT_WHITE * d * d * (s->mode == GN_MODE_PATH ? (float)M_PI : 1.0f);
    GnLight head;
    memset(&head, 0, sizeof head);
    head.type = GN_LIGHT_POINT;
    head.position = cam.position;
    head.direction = cam.forward;
    head.color = (vec3){intensity, intensity, intensity};
    sc->lights = util_realloc(sc->lights, (sc->num_lights + 1) * sizeof *sc->lights);
    sc->lights[sc->num_lights++] = head;
    s->env_map = NULL; /* (the local modes keep the studio's ambient term) */
    s->env[0] = s->env[1] = s->env[2] = 0;
    if (!quiet || util_strict())
        util_fallback("%s: the camera is inside a closed model (%.0f %% of the rays from it meet the scene) that "
                      "keeps the studio out (%.0f %% of the model lit): a headlight, a point light at the camera, "
                      "replaces the studio (any --env decides instead)", sc->path, 100 * enclosed, 100 * fmaxf(lit, 0));
    return true;
}

bool render_light_finish(const render_light_request *e, scene *sc, renderer *r, render_settings *s, bool quiet,
                         render_lighting *l)
{
    bool changed = false;
    /* The file's own light: is the view dark? (Not where the studio lights it already: for
     * the local modes its key light is among the scene's lights by now.) */
    if (!l->studio && env_probe_applies(e, sc)) {
        float lit = env_probe_lit_fraction(r, s, false);
        if (env_probe_is_dark(lit)) {
            env_add_studio(e, sc, quiet, lit, l, s);
            changed = s->mode != GN_MODE_PATH; /* the studio's key light joined the scene's lights */
        }
    }
    if (l->studio && !e->given && env_add_headlight(r, sc, s, quiet)) { /* a camera the studio cannot reach */
        l->headlight = changed = true;
        l->label = "headlight";
    }
    if (!changed)
        return true;
    gpu *g = r->g; /* the scene's lights changed: its renderer made again */
    renderer_destroy(r);
    return renderer_create(r, g, sc);
}

void render_lighting_destroy(render_lighting *l)
{
    image_destroy(&l->map);
    memset(l, 0, sizeof *l);
}
