/* cmd_brdf.c: `gonio brdf`, a virtual goniophotometer over the shader BRDF library: the
 * model list, polar plots of a lobe in the plane of incidence (Lambertian, specular,
 * combined), the directional albedo against incident angle (the energy-conservation
 * integral), and a material ball under a directional light
 * and a constant environment. Every number comes from glsl/lib/brdf_*.glsl run on the GPU. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brdf_runner.h"
#include "brdf_sphere.h" /* spv_brdf_sphere, generated from glsl/kernels/brdf_sphere.comp */
#include "cli.h"
#include "draw.h"
#include "image.h"
#include "render_material.h"
#include "util.h"
#include "vec.h"


static int bad_usage(const char *fmt, const char *arg)
{
    return cli_usage_error("brdf", fmt, arg);
}

/* The options before the model's parameters in cmd_brdf's table. */
#define BRDF_FIXED_OPTIONS 11

static bool take_param(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd;
    return brdf_setting_set(dest, opt + 2, val);
}


/* ---- lobe plot ------------------------------------------------------------------------ */

#define PLOT_N 3600 /* outgoing directions over the full circle: 0.1 degree apart */
#define MAX_CURVES 3
#define MAX_DIRAC 2

typedef struct plot_curve {
    const char *label;
    uint32_t color;
    double f[PLOT_N]; /* luminance of f at psi_k = -180 + 360 k / PLOT_N degrees */
} plot_curve;

typedef struct plot_dirac {
    double psi;         /* direction, degrees from the normal, signed as psi_k */
    double reflectance; /* luminance of the lobe's R (or T) */
} plot_dirac;

static double plot_psi(int k) { return -M_PI + 2 * M_PI * k / PLOT_N; }

/* f(wi, wo) in the x-z plane for light from (-sin theta, 0, cos theta). */
static void plot_eval(brdf_runner *r, const brdf_setting *s, double theta, double *out)
{
    BrdfQuery *q = util_calloc(PLOT_N, sizeof *q);
    BrdfResult *res = util_malloc(sizeof *res * PLOT_N);
    for (int k = 0; k < PLOT_N; k++) {
        brdf_setting_to_query(s, &q[k]);
        q[k].op = BRDF_OP_EVAL;
        q[k].wo = (vec3){(float)sin(plot_psi(k)), 0, (float)cos(plot_psi(k))};
        q[k].wi = (vec3){(float)-sin(theta), 0, (float)cos(theta)};
    }
    brdf_runner_run(r, q, res, PLOT_N);
    for (int k = 0; k < PLOT_N; k++)
        out[k] = vec_luminance(&res[k].f.x);
    free(q);
    free(res);
}

/* The Dirac lobes seen from the light direction (bsdf_sample from wo = wi: the mirror and
 * refracted directions), each with weight * probability = its reflectance. */
static int plot_dirac_lobes(brdf_runner *r, const brdf_setting *s, double theta, plot_dirac *out)
{
    enum { N = 256 };
    BrdfQuery q[N];
    BrdfResult res[N];
    int n = 0;
    uint32_t seen = 0;
    memset(q, 0, sizeof q);
    for (int k = 0; k < N; k++) {
        brdf_setting_to_query(s, &q[k]);
        q[k].op = BRDF_OP_SAMPLE;
        q[k].wo = (vec3){(float)-sin(theta), 0, (float)cos(theta)};
        q[k].u = (vec3){(k + 0.5f) / N, 0.5f, 0.5f};
    }
    brdf_runner_run(r, q, res, N);
    for (int k = 0; k < N && n < MAX_DIRAC; k++) {
        uint32_t kind = res[k].s_flags & (BRDF_FLAG_REFLECTION | BRDF_FLAG_TRANSMISSION);
        if (!(res[k].s_flags & BRDF_FLAG_DELTA) || (seen & kind))
            continue;
        seen |= kind;
        out[n].psi = atan2(res[k].s_wi.x, res[k].s_wi.z) * 180 / M_PI;
        out[n++].reflectance = vec_luminance(&res[k].s_weight.x) * res[k].s_pdf;
    }
    return n;
}

/* 1, 2 or 5 times a power of ten, near x. */
static double nice_step(double x)
{
    double p = pow(10, floor(log10(x))), m = x / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

/* How many characters of t fit a line of max_chars, breaking at a space where possible. */
static int wrap_at(const char *t, int max_chars)
{
    int n = (int)strlen(t), cut = max_chars;
    if (n <= max_chars)
        return n;
    while (cut > 0 && t[cut] != ' ')
        cut--;
    return cut > 0 ? cut : max_chars;
}

#define C_TEXT 0x202020ffu
#define C_GRID 0xd8d8d8ffu
#define C_AXIS 0x000000ffu
#define C_LIGHT 0xff8c00ffu
#define C_DIRAC 0x9467bdffu

static bool plot_write(const char *path, int w, int h, const char *title, double theta, bool full,
                       const plot_curve *curves, int num_curves, const plot_dirac *dirac, int num_dirac)
{
    draw_canvas c;
    char buf[128];
    double fmax = 0, step, top;
    float cx = 0.5f * (float)w, cy, rad;
    bool ok;
    if (full) {
        cy = 0.5f * (float)h + 10;
        rad = fminf(0.5f * (float)w, 0.5f * (float)h) - 50;
    } else {
        cy = (float)h - 40;
        rad = fminf(0.5f * (float)w - 50, (float)h - 100);
    }
    for (int i = 0; i < num_curves; i++)
        for (int k = 0; k < PLOT_N; k++)
            fmax = fmax > curves[i].f[k] ? fmax : curves[i].f[k];
    step = nice_step(fmax > 0 ? fmax / 4 : 0.25);
    top = step * ceil((fmax > 0 ? fmax : 1) / step - 1e-9);

    draw_create(&c, w, h);
    draw_clear(&c, 0xffffffffu);
    /* value rings, labelled along the right half of the surface line */
    for (double v = step; v <= top * (1 + 1e-9); v += step)
        draw_circle(&c, cx, cy, (float)(v / top) * rad, 1, C_GRID);
    if (!full) /* the rings are drawn whole; the plot is the upper half */
        draw_fill_rect(&c, 0, (int)cy + 1, w, h, 0xffffffffu);
    for (double v = step; v <= top * (1 + 1e-9); v += step) {
        float r = (float)(v / top) * rad;
        snprintf(buf, sizeof buf, "%g", v);
        draw_text(&c, (int)(cx + r) - draw_text_width(buf, 1) / 2, (int)cy + 4, 1, C_TEXT, buf);
    }
    /* angle spokes every 30 degrees from the normal, labelled at the rim */
    for (int deg = full ? -150 : -90; deg <= (full ? 180 : 90); deg += 30) {
        double a = deg * M_PI / 180;
        float x = (float)sin(a), y = (float)cos(a);
        draw_line(&c, cx, cy, cx + rad * x, cy - rad * y, 1, C_GRID);
        snprintf(buf, sizeof buf, "%d", abs(deg));
        draw_text(&c, (int)(cx + (rad + 14) * x) - draw_text_width(buf, 1) / 2,
                  (int)(cy - (rad + 14) * y) - DRAW_GLYPH_H / 2, 1, C_TEXT, buf);
    }
    /* the surface and its normal */
    draw_line(&c, cx - rad - 8, cy, cx + rad + 8, cy, 2, C_AXIS);
    draw_line(&c, cx, cy, cx, cy - rad - 4, 1, C_AXIS);
    draw_text(&c, (int)cx + 4, (int)(cy - rad) - 2, 1, C_TEXT, "n");
    draw_text(&c, (int)(cx + rad) - draw_text_width("f [1/sr]", 1), (int)cy + 16, 1, C_TEXT, "f [1/sr]");
    /* the incident light, an arrow toward the surface point */
    {
        float dx = -(float)sin(theta), dy = -(float)cos(theta); /* screen direction to the light */
        float hx = cx + 0.1f * rad * dx, hy = cy + 0.1f * rad * dy;
        draw_line(&c, cx + 0.95f * rad * dx, cy + 0.95f * rad * dy, hx, hy, 3, C_LIGHT);
        draw_line(&c, hx, hy, hx + 14 * dx - 6 * dy, hy + 14 * dy + 6 * dx, 3, C_LIGHT);
        draw_line(&c, hx, hy, hx + 14 * dx + 6 * dy, hy + 14 * dy - 6 * dx, 3, C_LIGHT);
    }
    /* Dirac lobes: arrows of length R x rim */
    for (int i = 0; i < num_dirac; i++) {
        double a = dirac[i].psi * M_PI / 180;
        float x = (float)sin(a), y = (float)cos(a), r = (float)dirac[i].reflectance * rad;
        draw_line(&c, cx, cy, cx + r * x, cy - r * y, 3, C_DIRAC);
        snprintf(buf, sizeof buf, "%.3f", dirac[i].reflectance);
        draw_text(&c, (int)(cx + (r + 10) * x) - draw_text_width(buf, 1) / 2, (int)(cy - (r + 10) * y) - 3, 1,
                  C_DIRAC, buf);
    }
    /* the lobes, radius = f */
    for (int i = 0; i < num_curves; i++) {
        for (int k = 0; k < PLOT_N; k++) {
            int k1 = (k + 1) % PLOT_N;
            double a0 = plot_psi(k), a1 = plot_psi(k1);
            float r0 = (float)(curves[i].f[k] / top) * rad, r1 = (float)(curves[i].f[k1] / top) * rad;
            if (r0 == 0 && r1 == 0)
                continue;
            draw_line(&c, cx + r0 * (float)sin(a0), cy - r0 * (float)cos(a0), cx + r1 * (float)sin(a1),
                      cy - r1 * (float)cos(a1), 2, curves[i].color);
        }
    }
    /* title (wrapped at spaces) and legend */
    int y = 8;
    for (const char *t = title; *t; y += 12) {
        int n = wrap_at(t, (w - 16) / DRAW_GLYPH_ADVANCE);
        snprintf(buf, sizeof buf, "%.*s", n, t);
        draw_text(&c, 8, y, 1, C_TEXT, buf);
        t += n + (t[n] == ' ');
    }
    snprintf(buf, sizeof buf, "f(wi, wo), wo in the plane of incidence; light at %g deg", theta * 180 / M_PI);
    draw_text(&c, 8, y, 1, C_TEXT, buf);
    {
        y += 20;
        draw_fill_rect(&c, 8, y + 2, 16, 3, C_LIGHT);
        draw_text(&c, 30, y, 1, C_TEXT, "incident light wi");
        for (int i = 0; i < num_curves; i++) {
            y += 12;
            draw_fill_rect(&c, 8, y + 2, 16, 3, curves[i].color);
            draw_text(&c, 30, y, 1, C_TEXT, curves[i].label);
        }
        if (num_dirac) {
            y += 12;
            draw_fill_rect(&c, 8, y + 2, 16, 3, C_DIRAC);
            draw_text(&c, 30, y, 1, C_TEXT, "Dirac lobe: length = R x rim");
        }
    }
    /* 16 levels per channel keep the anti-aliasing and make the PNG ~4x smaller */
    for (size_t i = 0; i < (size_t)w * (size_t)h * 4; i++)
        c.rgba[i] = (uint8_t)((c.rgba[i] * 15 + 127) / 255 * 17);
    ok = draw_write_png(&c, path);
    draw_destroy(&c);
    return ok;
}

static int run_plot(brdf_runner *r, const brdf_setting *s, double theta_deg, const char *out, int w, int h)
{
    plot_curve *curves = util_malloc(sizeof *curves * MAX_CURVES);
    plot_dirac dirac[MAX_DIRAC];
    char title[256];
    int n = 0, nd;
    double theta = theta_deg * M_PI / 180;
    const brdf_param *kd = brdf_param_find(s->model, "diffuse"), *ks = brdf_param_find(s->model, "specular");
    bool layered = kd && ks && s->model->id != BRDF_LAMBERT;
    bool full = brdf_setting_two_sided(s);
    brdf_format_title(title, sizeof title, s);
    curves[n] = (plot_curve){layered ? "combined: f = diffuse + specular" : "f", 0x1f4e9affu, {0}};
    plot_eval(r, s, theta, curves[n++].f);
    if (layered) { /* Lambertian, specular, combined */
        brdf_setting part = *s;
        part.v[ks->slot] = 0;
        curves[n] = (plot_curve){"Lambertian (diffuse) part", 0x2ca02cffu, {0}};
        plot_eval(r, &part, theta, curves[n++].f);
        part = *s;
        part.v[kd->slot] = part.v[kd->slot + 1] = part.v[kd->slot + 2] = 0;
        curves[n] = (plot_curve){"specular part", 0xd62728ffu, {0}};
        plot_eval(r, &part, theta, curves[n++].f);
    }
    nd = plot_dirac_lobes(r, s, theta, dirac);
    if (!w) {
        w = 560;
        h = full ? 560 : 360;
    }
    bool ok = plot_write(out, w, h, title, theta, full, curves, n, dirac, nd);
    free(curves);
    return ok ? 0 : 1;
}

/* ---- directional albedo ----------------------------------------------------------------- */

/* The white-furnace integral, int f cos dwi, as the mean sample weight over a
 * 3D low-discrepancy (Roberts' R3) sequence: deterministic and accurate to ~1e-3. */
static void run_albedo(brdf_runner *r, const brdf_setting *s)
{
    enum { N = 1 << 17 };
    static const double angles[] = {0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60, 65, 70, 75, 80, 85, 89};
    const double g = 1.2207440845122450, a[3] = {1 / g, 1 / (g * g), 1 / (g * g * g)};
    BrdfQuery *q = util_calloc(N, sizeof *q);
    BrdfResult *res = util_malloc(sizeof *res * N);
    for (size_t t = 0; t < sizeof angles / sizeof *angles; t++) {
        double th = angles[t] * M_PI / 180, sum[3] = {0};
        for (int i = 0; i < N; i++) {
            brdf_setting_to_query(s, &q[i]);
            q[i].op = BRDF_OP_SAMPLE;
            q[i].wo = (vec3){(float)sin(th), 0, (float)cos(th)};
            q[i].u = (vec3){(float)fmod(0.5 + a[0] * i, 1), (float)fmod(0.5 + a[1] * i, 1), (float)fmod(0.5 + a[2] * i, 1)};
        }
        brdf_runner_run(r, q, res, N);
        for (int i = 0; i < N; i++) {
            sum[0] += res[i].s_weight.x;
            sum[1] += res[i].s_weight.y;
            sum[2] += res[i].s_weight.z;
        }
        printf("%g %.5f %.5f %.5f\n", angles[t], sum[0] / N, sum[1] / N, sum[2] / N);
    }
    free(q);
    free(res);
}

/* ---- material ball ------------------------------------------------------------------------ */

static int run_sphere(gpu *g, const brdf_setting *s, const char *out, const char *png, int w, int h, int spp)
{
    BrdfQuery q;
    BrdfSphere ball;
    gpu_buffer sbuf, accum, sheen;
    gpu_pipeline p;
    image img;
    char desc[2048];
    const char *names[] = {"R", "G", "B"};
    vec4 *px = util_malloc(sizeof *px * (size_t)w * (size_t)h);
    bool ok = true;
    memset(&q, 0, sizeof q);
    memset(&ball, 0, sizeof ball);
    brdf_setting_to_query(s, &q);
    ball.material = q.material;
    ball.light_dir = (vec3){-0.5f / 0.9718f, 0.6f / 0.9718f, 0.55f / 0.9718f}; /* upper left, front */
    ball.light_irradiance = (vec3){2.5f, 2.5f, 2.5f};
    ball.env = (vec3){0.3f, 0.3f, 0.3f};
    ball.width = (uint32_t)w;
    ball.height = (uint32_t)h;
    ball.max_depth = 8;
    gpu_buffer_create_storage(g, &sbuf, &ball, sizeof ball);
    gpu_buffer_create(g, &accum, sizeof *px * (VkDeviceSize)w * (VkDeviceSize)h, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                      GPU_MEMORY_HOST);
    gpu_buffer_fill_zero(g, &accum);
    gpu_buffer_create_texels_as(g, &sheen, brdf_sheen_table, sizeof(float) * BRDF_SHEEN_TABLE_SIZE,
                                VK_FORMAT_R32_UINT);
    {
        const gpu_binding bind[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &sbuf},
                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &accum},
                                    {BRDF_BIND_SHEEN, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &sheen}};
        /* the kernel specialised on the material's features, as the renderer's are (every
         * feature with GONIO_ALL_FEATURES, which the tests compare it with) */
        GnFeatures features = getenv("GONIO_ALL_FEATURES") ? GN_FEAT_ALL : material_features(&ball.material);
        const uint32_t words[2] = {(uint32_t)features, (uint32_t)(features >> 32)};
        const VkSpecializationMapEntry entries[2] = {{GN_SPEC_FEATURES, 0, sizeof(uint32_t)},
                                                     {GN_SPEC_FEATURES_HI, sizeof(uint32_t), sizeof(uint32_t)}};
        VkSpecializationInfo spec = {2, entries, sizeof words, words};
        gpu_pipeline_desc pd = {.name = "brdf_sphere", .code = spv_brdf_sphere, .code_size = sizeof spv_brdf_sphere,
                                .local_size = {GN_TILE_X, GN_TILE_Y, 1}, .push_size = sizeof(GnPush),
                                .bindings = bind, .num_bindings = 3, .specialization = &spec};
        gpu_pipeline_create(g, &p, &pd);
    }
    /* a few samples per submission keeps every dispatch short (GPU watchdogs) */
    for (int done = 0; done < spp;) {
        VkCommandBuffer cmd = gpu_begin(g);
        for (int k = 0; k < 4 && done < spp; k++, done++) {
            GnPush push = {(uint32_t)done, 0, 0, 0};
            gpu_dispatch(cmd, &p, &push, (uint32_t)w, (uint32_t)h, 1);
            gpu_barrier(cmd);
        }
        gpu_submit_wait(g, cmd);
    }
    gpu_buffer_download(g, &accum, px, sizeof *px * (size_t)w * (size_t)h, 0);
    image_create(&img, w, h, 3, names);
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        img.planes[0][i] = px[i].x / px[i].w;
        img.planes[1][i] = px[i].y / px[i].w;
        img.planes[2][i] = px[i].z / px[i].w;
    }
    brdf_format_setting(desc, sizeof desc, s);
    {
        const image_attr attrs[] = {{"gonio:brdf", IMAGE_ATTR_STRING, desc, 0, 0, NULL},
                                    {"gonio:spp", IMAGE_ATTR_INT, NULL, spp, 0, NULL}};
        if (out)
            ok = image_write_exr(&img, out, attrs, 2);
    }
    if (ok && png)
        ok = image_write_png_from(&img, png, 0, IMAGE_TONEMAP_CLAMP);
    image_destroy(&img);
    gpu_pipeline_destroy(g, &p);
    gpu_buffer_destroy(g, &sheen);
    gpu_buffer_destroy(g, &accum);
    gpu_buffer_destroy(g, &sbuf);
    free(px);
    return ok ? 0 : 1;
}

/* ---- the command ---------------------------------------------------------------------------- */

int cmd_brdf(int argc, char **argv)
{
    const brdf_model *m = NULL;
    brdf_setting s;
    const char *out = NULL, *png = NULL;
    float theta = 30;
    bool albedo = false, sphere = false, validate = false, list = false;
    int size[2] = {0, 0}, spp = 64, device = -1, rc;
    gpu g;
    brdf_runner r;
    /* The model comes first: its parameters are options too. */
    if (argc >= 2 && argv[1][0] != '-') {
        if (!(m = brdf_model_find(argv[1])))
            return 2;
        brdf_setting_init(&s, m);
    }
    cli_option options[BRDF_FIXED_OPTIONS + BRDF_MAX_PARAMS] = {
        {"--list", NULL, "the models, one a line: name, then each parameter=default", CLI_FLAG, CLI_AS(bool, &list), 0, 0,
         NULL, NULL, NULL},
        {NULL, NULL, "  --PARAM VALUE       a model parameter (see --list); colours as R,G,B or one value\n",
         CLI_TEXT, NULL, 0, 0, NULL, NULL, NULL},
        {"--theta", "DEG", "lobe plot: incident (light) direction, degrees from the normal\n"
                           "(default 30); the curve is f(wi, wo) for wo in the plane of incidence",
         CLI_FLOAT, CLI_AS(float, &theta), 0, 90, "degrees in [0, 90]", NULL, NULL},
        {"--albedo", NULL, "print 'theta_deg albedo_r albedo_g albedo_b' for theta = 0, 5, ...,\n"
                           "85, 89: the directional albedo (reflected + transmitted fraction)\n"
                           "of light from theta",
         CLI_FLAG, CLI_AS(bool, &albedo), 0, 0, NULL, NULL, NULL},
        {"--sphere", NULL, "render a unit sphere of the material: directional light + constant sky",
         CLI_FLAG, CLI_AS(bool, &sphere), 0, 0, NULL, NULL, NULL},
        {"-o, --output", "FILE", "the lobe plot: a .png; the sphere: a .exr (linear float OpenEXR)\n"
                                 "or a .png (sRGB, clamped); any other name is a usage error",
         CLI_STRING, CLI_AS(const char *, &out), 0, 0, NULL, NULL, "*.exr *.png"},
        CLI_OPT_PNG(&png, "sphere: also a PNG (sRGB, clamped)"),
        CLI_OPT_SIZE(size, "image size (lobe default 560x360, 560x560 with transmission;\n"
                           "sphere 256x256)"),
        CLI_OPT_SPP(&spp, "sphere: samples per pixel (default 64)"),
        CLI_OPT_DEVICE(&device),
        CLI_OPT_VALIDATE(&validate),
    };
    char names[BRDF_MAX_PARAMS][48], help[BRDF_MAX_PARAMS][128];
    int n = BRDF_FIXED_OPTIONS;
    for (int i = 0; m && i < m->num_params; i++) { /* the model's parameters */
        const brdf_param *p = &m->params[i];
        snprintf(names[i], sizeof names[i], "--%s", p->name);
        if (p->count == 3 && (p->def[1] != p->def[0] || p->def[2] != p->def[0]))
            snprintf(help[i], sizeof help[i], "%s: in [%g, %g] (default %g,%g,%g)", m->name, p->min, p->max,
                     p->def[0], p->def[1], p->def[2]);
        else
            snprintf(help[i], sizeof help[i], "%s: in [%g, %g] (default %g)", m->name, p->min, p->max, p->def[0]);
        options[n++] = (cli_option){names[i], p->count == 3 ? "R,G,B" : "V", help[i], CLI_CALL, &s, 0, 0, NULL,
                                    take_param, NULL};
    }
    const cli_command command = {
        .name = "brdf",
        .synopsis = "--list\n"
                    "       gonio brdf MODEL [--PARAM VALUE ...] [--theta DEG] -o LOBE.png [--size WxH]\n"
                    "       gonio brdf MODEL [--PARAM VALUE ...] --albedo\n"
                    "       gonio brdf MODEL [--PARAM VALUE ...] --sphere -o BALL.exr|BALL.png [--png BALL.png]\n"
                    "                  [--size WxH] [--spp N]",
        .options = options, .num_options = n, .max_args = m ? 1 : 0,
        .complete_args = m ? NULL : cli_brdf_models(),
        .unknown_hint = " (gonio brdf --list: the models' parameters)"};
    cli_args args;
    if ((rc = cli_parse(&command, argc, argv, &args)) >= 0)
        return rc;
    if (list) {
        for (int i = 0; i < brdf_num_models; i++) {
            char line[1024]; /* the gltf model's line is over 300 characters */
            brdf_setting_init(&s, &brdf_models[i]);
            brdf_format_setting(line, sizeof line, &s);
            printf("%s\n", line);
        }
        return 0;
    }
    if (!m)
        return bad_usage("%s", "a model name or --list is needed");
    int w = size[0], h = size[1];
    if (albedo + sphere > 1)
        return bad_usage("%s", "--albedo and --sphere are separate modes: give one");
    if (!albedo && !out)
        return bad_usage("%s", "-o FILE is needed (a PNG for the lobe plot, an EXR for --sphere)");
    if (png && !sphere)
        return bad_usage("%s", "--png is for --sphere");
    if (albedo && out)
        return bad_usage("%s", "--albedo prints its table and writes no file: drop -o");
    /* The name says the format: the plot is drawn as PNG only; the sphere is an EXR or,
     * with -o BALL.png, the PNG alone. */
    if (out && !sphere && image_format_of(out) != IMAGE_FORMAT_PNG)
        return bad_usage("-o '%s': the lobe plot is a PNG: expected a .png name", out);
    if (out && sphere && image_format_of(out) == IMAGE_FORMAT_UNKNOWN)
        return bad_usage("-o '%s': expected a .exr (OpenEXR) or .png name", out);
    if (png && image_format_of(png) != IMAGE_FORMAT_PNG)
        return bad_usage("--png '%s': expected a .png name", png);
    if (sphere && image_format_of(out) == IMAGE_FORMAT_PNG) {
        if (png)
            return bad_usage("%s", "-o names a PNG already: drop --png");
        png = out;
        out = NULL;
    }
    if (sphere && (w > 4096 || h > 4096))
        return bad_usage("%s", "a sphere image is at most 4096x4096");
    if (!albedo && !sphere && w && (w < 240 || h < 240))
        return bad_usage("%s", "a lobe plot needs --size of at least 240x240");
    if ((out && !util_check_output(out)) || (png && !util_check_output(png)))
        return 1;
    if (!cli_gpu_create(&g, device, validate))
        return 1;
    if (sphere) {
        rc = run_sphere(&g, &s, out, png, w ? w : 256, h ? h : 256, spp);
    } else {
        brdf_runner_create(&r, &g, 1u << 16);
        if (albedo) {
            run_albedo(&r, &s);
            rc = 0;
        } else {
            rc = run_plot(&r, &s, theta, out, w, h);
        }
        brdf_runner_destroy(&r);
    }
    if (!cli_gpu_finish(&g))
        rc = 1;
    return rc;
}
