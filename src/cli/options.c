/* options.c: the options several commands take (cli.h): the parsers of the shared values
 * (size, mode, tonemap, variant, EXR compression), the view (the camera: --camera,
 * --look-at, --fov; the environment: --env, --env-rotate, --env-intensity) and the rule that
 * turns the environment options into a render's light (env_setup). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "brdf.h"
#include "camera.h"
#include "cli.h"
#include "environment.h"
#include "image.h"
#include "render.h"
#include "util.h"
#include "vec.h"

/* ---- shared values ---------------------------------------------------------------------- */

bool cli_take_size(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    int *wh = dest;
    return util_parse_size(value, &wh[0], &wh[1]);
}

bool cli_take_mode(const char *cmd, const char *opt, const char *value, void *dest)
{
    int m = render_mode_from_name(value);
    if (m < 0) {
        cli_usage_error(cmd, "%s '%s': expected one of %s", opt, value, render_mode_list());
        return false;
    }
    *(uint32_t *)dest = (uint32_t)m;
    return true;
}

bool cli_take_tonemap(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    return image_tonemap_from_name(value, dest);
}

bool cli_take_variant(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)dest;
    if (!*value) {
        cli_usage_error(cmd, "%s '': a variant's name (gonio info lists them)", opt);
        return false;
    }
    scene_select_variant(value);
    return true;
}

bool cli_take_exr_compression(const char *cmd, const char *opt, const char *value, void *dest)
{
    (void)cmd, (void)opt;
    return image_exr_compression_from_name(value, dest);
}

const char *cli_brdf_models(void)
{
    static char list[512];
    const char *names[64];
    int n = 0;
    for (int i = 0; i < brdf_num_models && n < 64; i++)
        names[n++] = brdf_models[i].name;
    return list[0] ? list : util_join(list, sizeof list, names, n);
}

/* ---- the camera ------------------------------------------------------------------------- */

/* Parses n comma-separated finite floats (n in [min_n, max_n]); returns how many, 0 on error. */
static int parse_floats(const char *s, float *out, int min_n, int max_n)
{
    int n = 0;
    const char *p = s;
    char *end = NULL;
    while (n < max_n) {
        float v = strtof(p, &end);
        if (end == p || !isfinite(v))
            return 0;
        out[n++] = v;
        if (*end == 0)
            break;
        if (*end != ',')
            return 0;
        p = end + 1;
    }
    return n >= min_n && *end == 0 ? n : 0;
}

/* --camera FILE.exr: the view gonio recorded in the file's header (camera_record_attrs). */
static int camera_from_exr(camera_option *c, const char *cmd, const char *path)
{
    char view[256];
    double fov = 0, ortho = 0;
    int fd = util_open_read(path); /* a missing file, a FIFO: its own message, nothing more */
    if (fd < 0)
        return 2;
    close(fd);
    if (!image_exr_attr_string(path, "gonio:look-at", view, sizeof view))
        return cli_usage_error(cmd, "--camera '%s': not an EXR with a gonio:look-at header (written by "
                                    "gonio render or preview)", path);
    float v[9];
    if (parse_floats(view, v, 9, 9) != 9)
        return cli_usage_error(cmd, "--camera '%s': gonio:look-at '%s' is not 9 numbers", path, view);
    image_exr_attr_double(path, "gonio:fov", &fov);
    image_exr_attr_double(path, "gonio:ortho-half-height", &ortho);
    if (!(fov > 0 && fov < 180) && !(ortho > 0 && isfinite(ortho)))
        return cli_usage_error(cmd, "--camera '%s': no valid gonio:fov or gonio:ortho-half-height", path);
    c->kind = CAMERA_LOOK_AT;
    memcpy(c->eye, v, sizeof c->eye);
    memcpy(c->target, v + 3, sizeof c->target);
    memcpy(c->up, v + 6, sizeof c->up);
    c->ortho_half_height = ortho > 0 ? (float)ortho : 0;
    /* The exact frame, when recorded: the look-at form loses the last bits of the view
     * direction (target - eye), which moves some silhouette pixels. */
    if (image_exr_attr_string(path, "gonio:view", view, sizeof view) && parse_floats(view, c->frame, 15, 15) == 15)
        c->exact = true;
    if (!image_exr_size(path, &c->width, &c->height))
        c->width = c->height = 0;
    if (c->fov == 0 && fov > 0 && !c->exact) /* gonio:view has the exact yfov */
        c->fov = (float)fov;
    return 1;
}

static int camera_parse_option(camera_option *c, const char *cmd, const char *opt, const char *val)
{
    long v;
    if (!strcmp(opt, "--camera")) {
        if (!strcmp(val, "frame")) {
            c->kind = CAMERA_FRAME;
        } else if (util_has_suffix(val, ".exr")) {
            return camera_from_exr(c, cmd, val);
        } else if (util_parse_int(val, 0, 1 << 20, &v)) {
            c->kind = CAMERA_INDEX;
            c->index = (int)v;
        } else {
            return cli_usage_error(cmd, "--camera '%s': expected an index in [0, %d], 'frame' or FILE.exr", val,
                                   1 << 20);
        }
        return 1;
    }
    if (!strcmp(opt, "--look-at")) {
        float f[9] = {0, 0, 0, 0, 0, 0, 0, 1, 0};
        int n = parse_floats(val, f, 6, 9);
        if (n != 6 && n != 9)
            return cli_usage_error(cmd, "--look-at '%s': expected EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ]", val);
        scene_camera probe;
        if (!camera_look_at_frame(f, f + 3, f + 6, &probe))
            return cli_usage_error(cmd, "--look-at '%s': the target must differ from the eye and the "
                                        "up vector must not point along the view", val);
        c->kind = CAMERA_LOOK_AT;
        c->exact = false;
        memcpy(c->eye, f, sizeof c->eye);
        memcpy(c->target, f + 3, sizeof c->target);
        memcpy(c->up, f + 6, sizeof c->up);
        c->ortho_half_height = 0;
        return 1;
    }
    if (!strcmp(opt, "--fov")) {
        float f;
        if (!util_parse_float(val, &f) || !(f > 0 && f < 180))
            return cli_usage_error(cmd, "--fov '%s': expected degrees in (0, 180)", val);
        c->fov = f;
        return 1;
    }
    return 0;
}

bool cli_take_camera(const char *cmd, const char *opt, const char *val, void *dest)
{
    return camera_parse_option((camera_option *)dest, cmd, opt, val) == 1;
}

/* ---- the environment -------------------------------------------------------------------- */

/* Radiance beyond this overflows the flux products in float (--env 1e38 wrote NaN pixels). */
#define ENV_MAX 1e9f

static int env_parse_option(env_option *e, const char *cmd, const char *opt, const char *val)
{
    if (!strcmp(opt, "--env")) {
        e->given = true;
        e->path = NULL;
        e->studio = !strcmp(val, "studio");
        if (e->studio)
            return 1;
        if (util_has_suffix(val, ".exr") || util_has_suffix(val, ".hdr"))
            e->path = val;
        else if (!util_parse_rgb(val, e->color) || e->color[0] > ENV_MAX || e->color[1] > ENV_MAX || e->color[2] > ENV_MAX)
            return cli_usage_error(cmd, "--env '%s': expected R,G,B or one value in [0, %g], FILE.exr, FILE.hdr or studio",
                                   val, ENV_MAX);
        return 1;
    }
    if (!strcmp(opt, "--env-rotate")) {
        if (!util_parse_float(val, &e->rotation) || !isfinite(e->rotation))
            return cli_usage_error(cmd, "--env-rotate '%s': expected degrees", val);
        return 1;
    }
    if (!strcmp(opt, "--env-intensity")) {
        if (!util_parse_float(val, &e->intensity) || !(e->intensity > 0) || !(e->intensity <= ENV_MAX))
            return cli_usage_error(cmd, "--env-intensity '%s': expected a number in (0, %g]", val, ENV_MAX);
        return 1;
    }
    return 0;
}

bool cli_take_env(const char *cmd, const char *opt, const char *val, void *dest)
{
    return env_parse_option((env_option *)dest, cmd, opt, val) == 1;
}

/* The studio in map; the local modes see it as its key light (added to sc's lights) plus
 * the mean of the rest. */
static void studio_setup(const env_option *e, scene *sc, bool local, image *map)
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

bool env_setup(const env_option *e, scene *sc, bool quiet, image *map, render_settings *s, bool *studio_used)
{
    float scale = e->intensity > 0 ? e->intensity : 1, mean[3] = {0, 0, 0};
    bool local = s->mode != GN_MODE_PATH;
    *studio_used = false;
    memset(map, 0, sizeof *map);
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
            *studio_used = true;
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

static bool env_probe_applies(const env_option *e, const scene *sc)
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
        float lum = 0.2126f * img.planes[ch[0]][i] + 0.7152f * img.planes[ch[1]][i] + 0.0722f * img.planes[ch[2]][i];
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

static void env_add_studio(const env_option *e, scene *sc, bool quiet, float lit, bool ambient_given,
                           image *map, render_settings *s)
{
    float scale = e->intensity > 0 ? e->intensity : 1, mean[3];
    if (!quiet)
        util_info("%s: its own light leaves the view dark (%.0f %% of the model brighter than %g, under %.0f %%): "
                  "added gonio's studio environment (--env 0 for the file's light alone)",
                  sc->path, 100 * lit, ENV_PROBE_LEVEL, 100 * ENV_PROBE_LIT);
    image_destroy(map);
    studio_setup(e, sc, s->mode != GN_MODE_PATH, map);
    env_use_map(map, scale, mean, s);
    if (!ambient_given)
        for (int k = 0; k < 3; k++)
            s->ambient[k] += mean[k];
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
    if (!quiet)
        util_info("%s: the camera is inside a closed model (%.0f %% of the rays from it meet the scene) that keeps "
                  "the studio out (%.0f %% of the model lit): a headlight, a point light at the camera, replaces "
                  "the studio (any --env decides instead)", sc->path, 100 * enclosed, 100 * fmaxf(lit, 0));
    return true;
}

bool env_light_rule(const env_option *e, scene *sc, renderer *r, render_settings *s, image *map, bool quiet,
                    bool ambient_given, bool *studio, bool *headlight)
{
    bool changed = false;
    *headlight = false;
    if (env_probe_applies(e, sc)) { /* the file's own light: is the view dark? */
        float lit = env_probe_lit_fraction(r, s, false);
        if (env_probe_is_dark(lit)) {
            env_add_studio(e, sc, quiet, lit, ambient_given, map, s);
            *studio = true;
            changed = s->mode != GN_MODE_PATH; /* the studio's key light joined the scene's lights */
        }
    }
    if (*studio && !e->given && env_add_headlight(r, sc, s, quiet)) /* a camera the studio cannot reach */
        *headlight = changed = true;
    return changed;
}
