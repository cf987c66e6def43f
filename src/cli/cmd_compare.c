/* cmd_compare.c: `gonio compare`: the three classic shading algorithms (flat, Gouraud, Phong
 * shading) and the path tracer rendered from one scene, side by side, with difference heat
 * maps and image metrics (image.h); and `--sweep`, the error of flat and Gouraud shading
 * against per-pixel Phong shading as the teapot's tessellation gets finer. */
#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "camera.h"
#include "cli.h"
#include "draw.h"
#include "environment.h"
#include "image.h"
#include "progress.h"
#include "render.h"
#include "scene.h"
#include "util.h"

/* The local modes differ from pixel to pixel only by the jitter of their camera rays, so a
 * few samples anti-alias them; more only cost time. */
#define COMPARE_LOCAL_SPP 16
#define COMPARE_MAX_MODES 4
#define COMPARE_MAX_LEVELS 16
#define COMPARE_MAX_DIR 4000
#define COMPARE_GAP 4          /* pixels between the tiles of the side-by-side image */
#define COMPARE_PERCENTILE 0.99 /* heat maps saturate at this quantile of the errors */

typedef struct compare_opts {
    const char *dir;
    uint32_t modes[COMPARE_MAX_MODES];
    int num_modes;
    int spp, width, height, device;
    int size[2]; /* --size */
    bool size_given, validate, quiet;
    camera_option camera;   /* the rule of every command (src/scene/camera.h) */
    scene_camera view;      /* ... resolved for the scene being compared */
    env_option env;         /* the light rule of every command (src/render/render_default_light.h) */
} compare_opts;

/* ---- rendering ---------------------------------------------------------------------------- */

/* The camera for sc (the shared rule) and, without --size, the image size it suggests. */
static bool choose_view(const scene *sc, compare_opts *o)
{
    float aspect = o->size_given ? (float)o->width / (float)o->height : 1.0f;
    if (!camera_resolve(&o->camera, sc, aspect, &o->view))
        return false;
    if (!o->size_given) {
        camera_default_size(&o->view, 320, &o->width, &o->height);
        if (o->width != 320) { /* 320 wide, as before, whatever the aspect */
            o->height = (int)fmaxf(1.0f, 320.0f * o->height / o->width + 0.5f);
            o->width = 320;
        }
        camera_resolve(&o->camera, sc, (float)o->width / (float)o->height, &o->view);
    }
    return true;
}

/* One mode's image; lit: the settings' light (render_light_begin), NULL: the scene's own. */
static bool render_one(renderer *r, const compare_opts *o, const render_settings *lit, uint32_t mode, image *out)
{
    render_stats st;
    cli_progress progress;
    render_settings s = lit ? *lit : (render_settings){0};
    s.mode = mode;
    s.width = o->width;
    s.height = o->height;
    s.spp = mode == GN_MODE_PATH || o->spp < COMPARE_LOCAL_SPP ? o->spp : COMPARE_LOCAL_SPP;
    s.view = &o->view;
    s.progress = o->quiet ? NULL : cli_progress_report;
    s.progress_user = &progress;
    return renderer_render(r, &s, out, &st);
}

/* The modes of o that the path kernel renders (path) or the local one (!path), into imgs[i]
 * for o->modes[i], from sc under the light rule for that kernel (which can add lights to sc;
 * said unless quiet). */
static bool render_kind(gpu *g, scene *sc, const compare_opts *o, bool path, bool quiet, image *imgs)
{
    render_settings lit = {.mode = path ? GN_MODE_PATH : GN_MODE_PHONG, .width = o->width, .height = o->height,
                           .spp = 1, .camera = -1, .view = &o->view};
    render_lighting light = {0};
    renderer r = {0};
    bool ok = render_light_begin(&o->env, sc, quiet, &lit, &light);
    if (ok) {
        renderer_create(&r, g, sc);
        ok = render_light_finish(&o->env, sc, &r, &lit, quiet, &light);
    }
    for (int i = 0; i < o->num_modes && ok; i++)
        if ((o->modes[i] == GN_MODE_PATH) == path)
            ok = render_one(&r, o, &lit, o->modes[i], &imgs[i]);
    renderer_destroy(&r);
    lit.env_map = NULL;
    render_lighting_destroy(&light);
    return ok;
}

/* Every mode of o rendered from the scene `input` (sc: loaded, its view chosen), the local
 * modes and the path tracer each under the light rule (the studio is the local modes' key
 * light and ambient, the path tracer's environment, as gonio render has it): the scene is
 * loaded again for the second kind when the first changed its lights. */
static bool render_every_mode(gpu *g, scene *sc, const char *input, int scene_index, const compare_opts *o, image *imgs)
{
    bool local = false, path = false;
    for (int i = 0; i < o->num_modes; i++)
        *(o->modes[i] == GN_MODE_PATH ? &path : &local) = true;
    if (local && !render_kind(g, sc, o, false, o->quiet, imgs))
        return false;
    if (local && path) {
        scene_destroy(sc);
        if (!scene_load_scene(sc, input, scene_index))
            return false;
    }
    return !path || render_kind(g, sc, o, true, o->quiet || local, imgs);
}

/* ---- pictures --------------------------------------------------------------------------- */

/* dir is at most COMPARE_MAX_DIR characters (checked on the command line). */
static void join(char *out, size_t cap, const char *dir, const char *name)
{
    int len = snprintf(out, cap, "%s/%s", dir, name);
    assert(len > 0 && (size_t)len < cap);
    (void)len;
}

/* Per-pixel |a - b|, the mean over R, G, B. */
static float *error_map(const image *a, const image *b)
{
    size_t n = (size_t)a->width * a->height;
    float *e = util_malloc(n * sizeof *e);
    for (size_t p = 0; p < n; p++) {
        e[p] = 0;
        for (int c = 0; c < 3; c++)
            e[p] += fabsf(a->planes[c][p] - b->planes[c][p]) / 3;
    }
    return e;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The COMPARE_PERCENTILE quantile of the non-zero errors (the background agrees exactly). */
static float error_quantile(const float *e, size_t n)
{
    float *v = util_malloc((n + 1) * sizeof *v), q;
    size_t m = 0;
    for (size_t p = 0; p < n; p++)
        if (e[p] > 0 && isfinite(e[p]))
            v[m++] = e[p];
    qsort(v, m, sizeof *v, cmp_float);
    q = m ? v[(size_t)(COMPARE_PERCENTILE * (double)(m - 1))] : 0;
    free(v);
    return q;
}

/* The smallest of 1, 2, 5 times a power of ten that is >= x (a legend's round number). */
static float nice_ceil(float x)
{
    double p;
    if (!(x > 0))
        return 1e-3f;
    p = pow(10, floor(log10(x)));
    return (float)(x <= p ? p : x <= 2 * p ? 2 * p : x <= 5 * p ? 5 * p : 10 * p);
}

static int label_scale(int width) { return width >= 240 ? 2 : 1; }

/* Heat map of e over [0, scale] (viridis) with a title above and a legend bar below. */
static bool write_heatmap(const char *path, const float *e, int w, int h, float scale,
                          const char *title)
{
    const int ts = label_scale(w), top = DRAW_GLYPH_H * ts + 8, bottom = 36;
    draw_canvas c;
    char lab[32];
    bool ok;
    draw_create(&c, w, h + top + bottom);
    draw_clear(&c, 0x000000ffu);
    draw_text(&c, 4, 4, ts, 0xffffffffu, title);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            draw_pixel(&c, x, top + y, draw_colormap(e[(size_t)y * w + x] / scale));
    /* Legend: the colour bar from 0 to scale, labelled at both ends and the middle. */
    for (int x = 8; x < w - 8; x++)
        draw_fill_rect(&c, x, top + h + 4, 1, 12, draw_colormap((float)(x - 8) / (float)(w - 17)));
    draw_text(&c, 8, top + h + 20, 1, 0xffffffffu, "0");
    snprintf(lab, sizeof lab, "%g", scale / 2);
    draw_text(&c, w / 2 - draw_text_width(lab, 1) / 2, top + h + 20, 1, 0xffffffffu, lab);
    snprintf(lab, sizeof lab, ">=%g", scale);
    draw_text(&c, w - 8 - draw_text_width(lab, 1), top + h + 20, 1, 0xffffffffu, lab);
    ok = draw_write_png(&c, path);
    draw_destroy(&c);
    return ok;
}

/* The images in a row, each under its label. */
static bool write_side_by_side(const char *path, const image *imgs, char labels[][64], int n)
{
    const int w = imgs[0].width, h = imgs[0].height, ts = label_scale(w);
    const int top = DRAW_GLYPH_H * ts + 8;
    uint8_t *rgba = util_malloc((size_t)w * h * 4);
    draw_canvas c;
    bool ok;
    draw_create(&c, n * w + (n - 1) * COMPARE_GAP, h + top);
    draw_clear(&c, 0x202020ffu);
    for (int i = 0; i < n; i++) {
        int x = i * (w + COMPARE_GAP);
        image_to_srgb8(imgs[i].planes[0], imgs[i].planes[1], imgs[i].planes[2], w, h, 0,
                       IMAGE_TONEMAP_CLAMP, rgba);
        draw_blit(&c, x, top, rgba, w, h);
        draw_text(&c, x + 4, 4, ts, 0xffffffffu, labels[i]);
    }
    ok = draw_write_png(&c, path);
    draw_destroy(&c);
    free(rgba);
    return ok;
}

/* ---- compare ------------------------------------------------------------------------------ */

typedef struct compare_row {
    uint32_t mode, ref;
    image_metrics m;
} compare_row;

/* A CSV file at path with its header line: the stream for its rows (util_out_commit ends it),
 * or NULL after an error. */
static FILE *csv_open(util_out *out, const char *path, const char *header)
{
    FILE *f;
    if (!util_out_open(out, path))
        return NULL;
    if (!(f = util_out_file(out))) {
        util_out_commit(out, false);
        return NULL;
    }
    fputs(header, f);
    return f;
}

static bool write_metrics(const char *path, const compare_row *rows, int n, bool print)
{
    util_out out;
    FILE *f = csv_open(&out, path, "mode,reference,rmse,rel_bias,max_err\n");
    if (!f)
        return false;
    if (print)
        printf("%-8s %-9s %10s %10s %10s\n", "mode", "reference", "rmse", "rel_bias", "max_err");
    for (int i = 0; i < n; i++) {
        const char *a = render_mode_name(rows[i].mode), *b = render_mode_name(rows[i].ref);
        const image_metrics *m = &rows[i].m;
        fprintf(f, "%s,%s,%.6g,%.6g,%.6g\n", a, b, m->rmse, m->rel_bias, m->max_err);
        if (print)
            printf("%-8s %-9s %10.5f %+10.4f %10.4f\n", a, b, m->rmse, m->rel_bias, m->max_err);
    }
    return util_out_commit(&out, true);
}

/* The files of a comparison of the images of o's modes (imgs[i] of o->modes[i]). */
static bool run_compare(image *imgs, const compare_opts *o)
{
    const uint32_t *modes = o->modes;
    char labels[COMPARE_MAX_MODES][64], path[4200], name[96];
    compare_row rows[2 * COMPARE_MAX_MODES];
    float *maps[2 * COMPARE_MAX_MODES] = {0}, scale[2] = {0, 0};
    int n = o->num_modes, num_rows = 0, phong = -1, path_i = -1;
    bool ok = true;
    for (int i = 0; i < n && ok; i++) {
        image_attr attr = {"gonio:mode", IMAGE_ATTR_STRING, render_mode_name(modes[i]), 0, 0, NULL};
        snprintf(name, sizeof name, "%s.exr", render_mode_name(modes[i]));
        join(path, sizeof path, o->dir, name);
        ok = image_write_exr(&imgs[i], path, &attr, 1);
        snprintf(name, sizeof name, "%s.png", render_mode_name(modes[i]));
        join(path, sizeof path, o->dir, name);
        ok = ok && image_write_png_from(&imgs[i], path, 0, IMAGE_TONEMAP_CLAMP);
        if (modes[i] == GN_MODE_PHONG) phong = i;
        if (modes[i] == GN_MODE_PATH) path_i = i;
    }
    /* Every mode against each reference present: per-pixel Phong, then the path tracer. */
    for (int ref = 0; ref < 2 && ok; ref++) {
        int j = ref ? path_i : phong;
        for (int i = 0; j >= 0 && i < n && ok; i++) {
            if (i == j)
                continue;
            rows[num_rows] = (compare_row){.mode = modes[i], .ref = modes[j]};
            ok = image_compare(&imgs[i], &imgs[j], &rows[num_rows].m);
            maps[num_rows] = error_map(&imgs[i], &imgs[j]);
            scale[ref] = fmaxf(scale[ref], error_quantile(maps[num_rows], (size_t)o->width * o->height));
            num_rows++;
        }
    }
    /* One scale for the maps against the same reference, so they can be compared. */
    for (int k = 0; k < num_rows && ok; k++) {
        char title[96];
        float sc = nice_ceil(scale[rows[k].ref == GN_MODE_PATH]);
        snprintf(name, sizeof name, "diff-%s-vs-%s.png", render_mode_name(rows[k].mode),
                 render_mode_name(rows[k].ref));
        snprintf(title, sizeof title, "|%s - %s|", render_mode_name(rows[k].mode),
                 render_mode_name(rows[k].ref));
        join(path, sizeof path, o->dir, name);
        ok = write_heatmap(path, maps[k], o->width, o->height, sc, title);
    }
    for (int i = 0; i < n && ok; i++) {
        const char *mn = render_mode_name(modes[i]);
        if (i == phong)
            snprintf(labels[i], sizeof labels[i], "phong (per pixel)");
        else if (i == path_i)
            snprintf(labels[i], sizeof labels[i], "path, %d spp", o->spp);
        else if (phong >= 0)
            for (int k = 0; k < num_rows; k++)
                if (rows[k].mode == modes[i] && rows[k].ref == GN_MODE_PHONG)
                    snprintf(labels[i], sizeof labels[i], "%s rmse %.4f", mn, rows[k].m.rmse);
        if (phong < 0 && i != path_i)
            snprintf(labels[i], sizeof labels[i], "%s", mn);
    }
    if (ok && n > 0) {
        join(path, sizeof path, o->dir, "side-by-side.png");
        ok = write_side_by_side(path, imgs, labels, n);
    }
    if (ok) {
        join(path, sizeof path, o->dir, "metrics.csv");
        ok = write_metrics(path, rows, num_rows, !o->quiet);
    }
    for (int k = 0; k < num_rows; k++)
        free(maps[k]);
    return ok;
}

/* ---- sweep -------------------------------------------------------------------------------- */

typedef struct sweep_row {
    int level;
    uint32_t triangles;
    image_metrics gouraud, flat;
} sweep_row;

/* log10 axis range covering [lo, hi] in whole decades. */
static void decades(double lo, double hi, int *a, int *b)
{
    *a = (int)floor(log10(lo));
    *b = (int)ceil(log10(hi));
    if (*b <= *a)
        *b = *a + 1;
}

/* RMSE against triangle count, log-log, one line per mode, each point marked with its level. */
static bool write_sweep_plot(const char *path, const sweep_row *rows, int n)
{
    const int W = 640, H = 440, L = 70, R = 20, T = 40, B = 56;
    const uint32_t colors[2] = {0xff7f0eff, 0x1f77b4ff}, ink = 0x202020ff, grid = 0xddddddff;
    const char *names[2] = {"gouraud vs phong", "flat vs phong"};
    double ylo = 1e30, yhi = 0;
    int x0, x1, y0, y1;
    draw_canvas c;
    bool ok;
    char lab[32];
    for (int i = 0; i < n; i++) {
        double v[2] = {rows[i].gouraud.rmse, rows[i].flat.rmse};
        for (int k = 0; k < 2; k++)
            if (v[k] > 0) {
                ylo = fmin(ylo, v[k]);
                yhi = fmax(yhi, v[k]);
            }
    }
    if (yhi <= 0)
        ylo = 1e-4, yhi = 1;
    decades(rows[0].triangles, rows[n - 1].triangles, &x0, &x1);
    decades(ylo, yhi, &y0, &y1);
#define PX(t) (L + (float)((log10(t) - x0) / (x1 - x0)) * (W - L - R))
#define PY(e) (H - B - (float)((log10(e) - y0) / (y1 - y0)) * (H - T - B))
    draw_create(&c, W, H);
    draw_clear(&c, 0xffffffffu);
    for (int k = x0; k <= x1; k++) {
        float x = PX(pow(10, k));
        draw_line(&c, x, T, x, H - B, 1, grid);
        snprintf(lab, sizeof lab, "1e%d", k);
        draw_text(&c, (int)x - draw_text_width(lab, 1) / 2, H - B + 6, 1, ink, lab);
    }
    for (int k = y0; k <= y1; k++) {
        float y = PY(pow(10, k));
        draw_line(&c, L, y, W - R, y, 1, grid);
        snprintf(lab, sizeof lab, "1e%d", k);
        draw_text(&c, L - 6 - draw_text_width(lab, 1), (int)y - 3, 1, ink, lab);
    }
    draw_rect(&c, L, T, W - L - R + 1, H - T - B + 1, ink);
    draw_text(&c, L, 12, 2, ink, "teapot: error against per-pixel Phong");
    draw_text(&c, (W + L - R) / 2 - draw_text_width("triangles", 2) / 2, H - 24, 2, ink, "triangles");
    draw_text(&c, 6, T - 14, 1, ink, "RMSE");
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < n; i++) {
            double e = k ? rows[i].flat.rmse : rows[i].gouraud.rmse;
            float x = PX(rows[i].triangles), y;
            if (!(e > 0))
                continue;
            y = PY(e);
            if (i > 0 && (k ? rows[i - 1].flat.rmse : rows[i - 1].gouraud.rmse) > 0)
                draw_line(&c, PX(rows[i - 1].triangles),
                          PY(k ? rows[i - 1].flat.rmse : rows[i - 1].gouraud.rmse), x, y, 2, colors[k]);
            draw_circle(&c, x, y, 3.5f, 2, colors[k]);
            if (k == 0) {
                snprintf(lab, sizeof lab, "L%d", rows[i].level);
                draw_text(&c, (int)x + 5, (int)y + 5, 1, ink, lab);
            }
        }
        draw_line(&c, W - R - 150, T + 14 + 16 * k, W - R - 126, T + 14 + 16 * k, 2, colors[k]);
        draw_text(&c, W - R - 120, T + 11 + 16 * k, 1, ink, names[k]);
    }
#undef PX
#undef PY
    ok = draw_write_png(&c, path);
    draw_destroy(&c);
    return ok;
}

static bool write_sweep_csv(const char *path, const sweep_row *rows, int n, bool print)
{
    util_out out;
    FILE *f = csv_open(&out, path, "level,triangles,gouraud_rmse,gouraud_rel_bias,gouraud_max_err,"
                                   "flat_rmse,flat_rel_bias,flat_max_err\n");
    if (!f)
        return false;
    if (print)
        printf("%5s %9s %12s %12s %12s\n", "level", "triangles", "gouraud_rmse", "flat_rmse",
               "gouraud_max");
    for (int i = 0; i < n; i++) {
        const sweep_row *s = &rows[i];
        fprintf(f, "%d,%u,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", s->level, s->triangles,
                s->gouraud.rmse, s->gouraud.rel_bias, s->gouraud.max_err, s->flat.rmse,
                s->flat.rel_bias, s->flat.max_err);
        if (print)
            printf("%5d %9u %12.6f %12.6f %12.4f\n", s->level, s->triangles, s->gouraud.rmse,
                   s->flat.rmse, s->gouraud.max_err);
    }
    return util_out_commit(&out, true);
}

/* The teapot at each level through `gonio teapot` (into DIR, removed once loaded). */
static bool run_sweep(gpu *g, compare_opts *o, const int *levels, int n)
{
    sweep_row rows[COMPARE_MAX_LEVELS];
    char path[4200], gltf[4200], lev[16];
    bool ok = true;
    for (int i = 0; i < n && ok; i++) {
        char a0[] = "teapot", a1[] = "--level", a3[] = "-o";
        char *argv[] = {a0, a1, lev, a3, gltf, NULL};
        scene sc = {0};
        renderer r = {0};
        image phong = {0}, gouraud = {0}, flat = {0};
        snprintf(lev, sizeof lev, "%d", levels[i]);
        snprintf(path, sizeof path, "teapot-%d.gltf", levels[i]);
        join(gltf, sizeof gltf, o->dir, path);
        ok = cmd_teapot(5, argv) == 0 && scene_load(&sc, gltf);
        unlink(gltf);
        if (!ok)
            break;
        if (!choose_view(&sc, o)) {
            scene_destroy(&sc);
            ok = false;
            break;
        }
        renderer_create(&r, g, &sc);
        rows[i] = (sweep_row){.level = levels[i], .triangles = sc.num_triangles};
        ok = render_one(&r, o, NULL, GN_MODE_PHONG, &phong) && render_one(&r, o, NULL, GN_MODE_GOURAUD, &gouraud) &&
             render_one(&r, o, NULL, GN_MODE_FLAT, &flat) && image_compare(&gouraud, &phong, &rows[i].gouraud) &&
             image_compare(&flat, &phong, &rows[i].flat);
        image_destroy(&phong);
        image_destroy(&gouraud);
        image_destroy(&flat);
        renderer_destroy(&r);
        scene_destroy(&sc);
    }
    if (ok) {
        join(path, sizeof path, o->dir, "sweep.csv");
        ok = write_sweep_csv(path, rows, n, !o->quiet);
    }
    if (ok) {
        join(path, sizeof path, o->dir, "sweep.png");
        ok = write_sweep_plot(path, rows, n);
    }
    return ok;
}

/* ---- command line ------------------------------------------------------------------------- */

static bool parse_modes(const char *list, compare_opts *o)
{
    char buf[256], *tok, *save;
    o->num_modes = 0;
    if (strlen(list) >= sizeof buf)
        return false;
    strcpy(buf, list);
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int m = render_mode_from_name(tok);
        if (m < 0 || !(render_modes[m].kernel == GN_KERNEL_PATH || render_modes[m].flags & GN_MODEF_LIT))
            return false;
        for (int i = 0; i < o->num_modes; i++)
            if (o->modes[i] == (uint32_t)m)
                return false;
        o->modes[o->num_modes++] = (uint32_t)m;
    }
    return o->num_modes > 0;
}

/* "1,2,4": increasing levels 1..256. */
static bool parse_levels(const char *list, int *levels, int *n)
{
    const char *s = list;
    *n = 0;
    for (;;) {
        char buf[16];
        long v;
        size_t len = strcspn(s, ",");
        if (len == 0 || len >= sizeof buf || *n == COMPARE_MAX_LEVELS)
            return false;
        memcpy(buf, s, len);
        buf[len] = 0;
        if (!util_parse_int(buf, 1, 256, &v) || (*n > 0 && v <= levels[*n - 1]))
            return false;
        levels[(*n)++] = (int)v;
        s += len;
        if (!*s++)
            return true;
    }
}

static bool make_dir(const char *dir)
{
    struct stat st;
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        util_error("%s: cannot create the directory: %s", dir, strerror(errno));
        return false;
    }
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode) || access(dir, W_OK) != 0) {
        util_error("%s: not a writable directory", dir);
        return false;
    }
    return true;
}

#define COMPARE_INTRO                                                                          \
    "Renders a scene with flat, Gouraud and per-pixel Phong shading (the Phong reflection\n"   \
    "model of OpenGL 1.x) and path-traced, and writes into DIR:\n"                             \
    "  MODE.exr, MODE.png        each mode's image (linear float EXR; sRGB PNG, clamped)\n"     \
    "  side-by-side.png          the PNGs in a row, labelled with the mode and its RMSE\n"     \
    "  diff-A-vs-B.png           heat map of |A - B| (mean over R, G, B, viridis; the legend\n" \
    "                            gives the scale) for each mode against phong and path\n"       \
    "  metrics.csv               mode,reference,rmse,rel_bias,max_err (also printed)\n"         \
    "Each mode is lit as gonio render lights it: by the file's own lights, its image-based\n"  \
    "light, or gonio's studio environment (--env decides instead).\n"                         \
    "With --sweep, renders the teapot at each tessellation level (e.g. 1,2,4,8,16,32) and\n"   \
    "writes sweep.csv (flat's and Gouraud's error against per-pixel Phong shading, by\n"       \
    "triangle count) and sweep.png (the plot, log-log).\n"

typedef struct level_list {
    int v[COMPARE_MAX_LEVELS];
    int n;
} level_list;

static bool take_levels(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    level_list *l = dest;
    return parse_levels(val, l->v, &l->n);
}

static bool take_modes(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    return parse_modes(val, dest);
}

int cmd_compare(int argc, char **argv)
{
    compare_opts o = {.modes = {GN_MODE_FLAT, GN_MODE_GOURAUD, GN_MODE_PHONG, GN_MODE_PATH},
                      .num_modes = 4, .spp = 64, .device = -1};
    const char *input = NULL, *sweep = NULL;
    level_list sweep_levels = {.n = 0};
    int rc = 1, scene_index = -1;
    bool outside = false, strict = false;
    gpu g = {0};
    const cli_option options[] = {
        {"-o, --output", "DIR", "output directory (created if missing)", CLI_STRING, CLI_AS(const char *, &o.dir), 0, 0, NULL, NULL,
         "/"},
        {"--sweep", "LEVELS", "the teapot at these tessellation levels (see above)", CLI_CALL, &sweep_levels,
         0, 0, "up to 16 increasing levels 1..256, e.g. 1,2,4,8", take_levels, NULL},
        {"--modes", "LIST", "any of flat,gouraud,phong,path (default all four; phong and path\n"
                            "are the references)",
         CLI_CALL, &o, 0, 0, "a list of flat, gouraud, phong, path (each once)", take_modes,
         "flat gouraud phong path"},
        CLI_OPT_SPP(&o.spp, "path tracer samples per pixel (default 64); the local modes take\n"
                            "min(N, 16), which only anti-aliases them"),
        CLI_OPT_SIZE(o.size, "image size (default 320 wide, the camera's aspect)"),
        CAMERA_OPTIONS(&o.camera),
        ENV_OPTIONS(&o.env),
        CLI_OPT_SCENE(&scene_index, "compare the file's glTF scene N (default: its default scene)"),
        CLI_OPT_ALLOW_OUTSIDE_FILES(&outside),
        CLI_OPT_DEVICE(&o.device),
        CLI_OPT_VALIDATE(&o.validate),
        CLI_OPT_QUIET(&o.quiet, "no progress and no table"),
        CLI_OPT_STRICT(&strict),
    };
    const cli_command command = {
        .name = "compare", .synopsis = "SCENE.gltf -o DIR [options]\n"
                                       "       gonio compare --sweep LEVELS teapot -o DIR [options]",
        .intro = COMPARE_INTRO, CLI_OPTIONS(options), .max_args = 1, .complete_args = "*.gltf *.glb teapot"};
    cli_args args;
    if ((rc = cli_parse(&command, argc, argv, &args)) >= 0)
        return rc;
    rc = 1;
    if ((o.size_given = cli_given(&command, &args, "--size"))) {
        o.width = o.size[0];
        o.height = o.size[1];
    }
    input = args.num_args ? args.arg[0] : NULL;
    sweep = cli_given(&command, &args, "--sweep") ? "" : NULL;
    if (sweep && (cli_given(&command, &args, "--scene") || outside || o.env.given || o.env.rotation != 0 ||
                  o.env.intensity > 0))
        return cli_usage_error("compare", "--sweep renders gonio's teapot under its own light: --scene, "
                                          "--allow-outside-files and the --env options do not apply");
    scene_allow_outside_files(outside);
    if (!input)
        return cli_usage_error("compare", sweep ? "--sweep: no scene generator given (teapot)" : "no scene given");
    if (sweep && strcmp(input, "teapot"))
        return cli_usage_error("compare", "--sweep: unknown scene generator '%s' (teapot)", input);
    if (!o.dir)
        return cli_usage_error("compare", "no output directory given (-o DIR)");
    if (strlen(o.dir) > COMPARE_MAX_DIR)
        return cli_usage_error("compare", "-o: a directory name of at most %d characters", COMPARE_MAX_DIR);
    util_set_quiet(o.quiet);
    int since = cli_strict_begin(strict);
    if (!make_dir(o.dir))
        return 1;

    if (sweep) {
        if (cli_gpu_create(&g, o.device, o.validate))
            rc = run_sweep(&g, &o, sweep_levels.v, sweep_levels.n) ? 0 : 1;
    } else {
        scene sc = {0};
        image imgs[COMPARE_MAX_MODES] = {{0}};
        if (!scene_load_scene(&sc, input, scene_index))
            return 1;
        if (!cli_strict_ok(since, input)) {
            /* said */
        } else if (!choose_view(&sc, &o)) {
            /* camera_resolve said why */
        } else if (cli_gpu_create(&g, o.device, o.validate)) {
            rc = render_every_mode(&g, &sc, input, scene_index, &o, imgs) && cli_strict_ok(since, input) &&
                         run_compare(imgs, &o) ? 0 : 1;
        }
        for (int i = 0; i < COMPARE_MAX_MODES; i++)
            image_destroy(&imgs[i]);
        scene_destroy(&sc);
    }
    if (g.device && !cli_gpu_finish(&g))
        rc = 1;
    return rc;
}
