/* test_brdf.c: the BRDF library (glsl/lib/brdf_*.glsl) proven physical on the GPU through
 * glsl/kernels/brdf_test.comp: finiteness and positivity everywhere, Helmholtz reciprocity, energy
 * conservation (white-furnace albedo <= 1, = albedo for Lambert), sampling against the pdf
 * by a chi-square test (as pbrt-v4 and Mitsuba 3 do), pdf normalisation, weight = f cos/pdf,
 * the Fresnel equations against analytic values and a complex-arithmetic reference, the
 * Dirac lobes; a self-test shows the checks reject a pdf scaled by 1.1 and a missing 1/pi.
 * References are analytic or brute-force quadrature of eval, never sample() itself. */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "brdf_runner.h"
#include "test.h"
#include "util.h"

#define PI 3.14159265358979323846

/* A spread of physically valid settings (max(diffuse) + specular <= 1): wide and narrow
 * lobes, sums, Dirac lobes, both sides of dielectrics. */
typedef struct config {
    const char *model;
    const char *params; /* "name=value ..." */
} config;

static const config configs[] = {
    {"lambert", "diffuse=0.8,0.5,0.2"},
    {"lambert", "diffuse=1"},
    {"mirror", "reflectance=0.9,0.6,0.3"},
    {"phong", "exponent=1"},
    {"phong", "diffuse=0.5 specular=0.5 exponent=20"},
    {"phong", "exponent=200"},
    {"blinn-phong", "exponent=0"},
    {"blinn-phong", "diffuse=0.3 specular=0.7 exponent=50"},
    {"torrance-sparrow", "exponent=20"},
    {"torrance-sparrow", "diffuse=0.5 specular=0.5 exponent=300 ior=1.8"},
    {"beckmann", "alpha=0.5"},
    {"beckmann", "diffuse=0.5 specular=0.5 alpha=0.1 ior=2"},
    {"ggx", "alpha=0.7"},
    {"ggx", "diffuse=0.6 specular=0.4 alpha=0.15"},
    {"ggx", "diffuse=0.5 specular=0.5 alpha=0"},
    {"conductor", ""},
    {"conductor", "eta=1.5 k=0 alpha=0.5"},
    {"conductor", "alpha=0"},
    {"dielectric", ""},
    {"dielectric", "alpha=0.3"},
    {"dielectric", "alpha=0.1 ior=1.33 tint=0.8,0.9,1"},
    {"gltf", ""},
    {"gltf", "metallic=1 roughness=0.3 base-color=0.9,0.6,0.2"},
    {"gltf", "metallic=0.3 roughness=0.2 specular-color=1,0.5,0.5 ior=1.7"},
    {"gltf", "transmission=1 roughness=0.4"},
    {"gltf", "roughness=0"},
    {"gltf", "transmission=0.5 metallic=0.2 roughness=0"},
    /* the layers (KHR_materials_clearcoat, _sheen); tilt: the coat's normal, degrees */
    {"gltf", "clearcoat=1 clearcoat-roughness=0.3"},
    {"gltf", "clearcoat=0.7 metallic=1 roughness=0.5 base-color=0.9,0.5,0.2"},
    {"gltf", "clearcoat=1 clearcoat-roughness=0.1 roughness=0 base-color=0.1 tilt=20"},
    {"gltf", "sheen-color=1 sheen-roughness=0.5 base-color=0.2"},
    {"gltf", "sheen-color=1 sheen-roughness=0 base-color=1 specular=0"},
    {"gltf", "sheen-color=0.9,0.4,0.2 sheen-roughness=1 clearcoat=0.5 clearcoat-roughness=0.2 base-color=0.9"},
    {"gltf", "clearcoat=1 clearcoat-roughness=0.2 sheen-color=0.5 transmission=1 roughness=0.3"},
    {"gltf", "clearcoat=0.8 transmission=1 roughness=0"},
    /* KHR_materials_anisotropy: rotations in radians from the tangent (+x) */
    {"gltf", "metallic=1 roughness=0.3 base-color=0.9,0.6,0.2 anisotropy=0.8"},
    {"gltf", "roughness=0.5 anisotropy=1 anisotropy-rotation=0.7"},
    {"gltf", "roughness=0.2 anisotropy=0.6 anisotropy-rotation=2 specular-color=1,0.5,0.5"},
    {"gltf", "transmission=1 roughness=0.4 anisotropy=0.7 anisotropy-rotation=-1"},
    {"gltf", "clearcoat=0.5 clearcoat-roughness=0.2 roughness=0.3 metallic=0.5 anisotropy=0.9 anisotropy-rotation=1"},
    /* KHR_materials_iridescence, _diffuse_transmission (bsdf_gltf_film) */
    {"gltf", "iridescence=1 iridescence-thickness=400 roughness=0.3"},
    {"gltf", "iridescence=1 iridescence-ior=1.8 iridescence-thickness=250 metallic=1 base-color=0.9,0.6,0.2 roughness=0.5"},
    {"gltf", "iridescence=0.6 iridescence-thickness=800 roughness=0 base-color=1"},
    {"gltf", "iridescence=1 iridescence-ior=2 iridescence-thickness=150 metallic=0.5 roughness=0.25 base-color=1"},
    {"gltf", "iridescence=1 iridescence-thickness=350 transmission=1 roughness=0.3"},
    {"gltf", "iridescence=0.8 iridescence-ior=1.8 iridescence-thickness=500 transmission=1 roughness=0"},
    {"gltf", "diffuse-transmission=0.5 base-color=1 roughness=0.4"},
    {"gltf", "diffuse-transmission=1 diffuse-transmission-color=0.9,0.5,0.2 roughness=0"},
    {"gltf", "diffuse-transmission=0.7 diffuse-transmission-color=1 base-color=1 specular=0"},
    {"gltf", "diffuse-transmission=0.6 diffuse-transmission-color=1 base-color=1 iridescence=1 iridescence-thickness=300 "
             "clearcoat=0.5 clearcoat-roughness=0.2 sheen-color=0.5 sheen-roughness=0.4"},
};
#define NUM_CONFIGS ((int)(sizeof configs / sizeof *configs))

/* The settings the tests run over: configs, then every model of the table (brdf_models.h)
 * that configs give no default setting of, at its defaults: a model added to the table is
 * tested with no edit here. */
static config cases[NUM_CONFIGS + 64];
static int num_cases(void)
{
    static int n;
    if (n)
        return n;
    for (; n < NUM_CONFIGS; n++)
        cases[n] = configs[n];
    for (int i = 0; i < brdf_num_models; i++) {
        bool tested = false;
        for (int k = 0; k < NUM_CONFIGS; k++)
            tested |= !strcmp(configs[k].model, brdf_models[i].name) && !configs[k].params[0];
        if (!tested && n < (int)(sizeof cases / sizeof *cases))
            cases[n++] = (config){brdf_models[i].name, ""};
    }
    return n;
}

static bool make_setting(const config *c, brdf_setting *s)
{
    char buf[512], *save = NULL;
    const brdf_model *m = brdf_model_find(c->model);
    if (!m)
        return false;
    brdf_setting_init(s, m);
    snprintf(buf, sizeof buf, "%s", c->params);
    for (char *tok = strtok_r(buf, " ", &save); tok; tok = strtok_r(NULL, " ", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq)
            return false;
        *eq = 0;
        if (!strcmp(tok, "tilt"))
            s->coat_tilt = (float)(atof(eq + 1) * PI / 180);
        else if (!brdf_setting_set(s, tok, eq + 1))
            return false;
    }
    return true;
}

static const char *describe(const config *c)
{
    static char buf[300];
    snprintf(buf, sizeof buf, "%s %s", c->model, c->params);
    return buf;
}

/* ---- host helpers ------------------------------------------------------------------- */

static uint64_t rng_state;
static double rnd(void) /* splitmix64 -> [0, 1) */
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

static vec3 v3(double x, double y, double z) { return (vec3){(float)x, (float)y, (float)z}; }
static vec3 polar(double theta, double phi) { return v3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta)); }
static vec3 rnd_u(void) { return v3(rnd() * 0.99999994, rnd() * 0.99999994, rnd() * 0.99999994); }
static double rad(double deg) { return deg * PI / 180.0; }
static bool finite3(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static double sum3(vec3 v) { return (double)v.x + v.y + v.z; }

static BrdfQuery query(const brdf_setting *s, uint32_t op, vec3 wo, vec3 wi, vec3 u)
{
    BrdfQuery q;
    memset(&q, 0, sizeof q);
    brdf_setting_to_query(s, &q);
    q.op = op;
    q.wo = wo;
    q.wi = wi;
    q.u = u;
    return q;
}

static gpu test_gpu;
static brdf_runner runner;
#define CHUNK 65536 /* queries per batch: small buffers keep page faults (and ASan) cheap */
static BrdfQuery *qbuf; /* CHUNK queries and results, reused by every batch */
static BrdfResult *rbuf;
static int messages_before; /* validation messages when the running test began */

static void grid_init(void);

/* At exit: the runner and device the tests shared, destroyed; a validation message in
 * that makes the run fail. */
static void destroy_runner(void)
{
    brdf_runner_destroy(&runner);
    gpu_destroy(&test_gpu);
    free(qbuf);
    free(rbuf);
    if (gpu_validation_message_count() > messages_before) {
        fprintf(stderr, "test_brdf.c: validation messages while destroying the runner\n");
        _exit(1);
    }
}

/* The runner, its device and its kernels are made once a process and shared by the tests
 * (each specialised kernel is compiled once: brdf_runner keeps them). */
static bool open_runner(void)
{
    static bool opened, failed;
    if (!opened && !failed) {
        gpu_desc d = {.device_index = -1};
        const char *env = getenv("GONIO_VALIDATE");
        d.validate = env && !strcmp(env, "1");
        if (!gpu_create(&test_gpu, &d)) {
            failed = true;
        } else {
            brdf_runner_create(&runner, &test_gpu, CHUNK);
            grid_init();
            atexit(destroy_runner);
            opened = true;
        }
    }
    CHECKF(opened, "no Vulkan device");
    messages_before = gpu_validation_message_count();
    return opened;
}

/* The end of a test: no validation message while it ran. */
static void close_runner(void) { CHECK(gpu_validation_message_count() == messages_before); }

/* ---- statistics --------------------------------------------------------------------- */

/* Regularised upper incomplete gamma Q(a, x) (series below a + 1, continued fraction above,
 * as in Numerical Recipes 6.2): the chi-square tail is Q(dof / 2, chi2 / 2). */
static double gamma_q(double a, double x)
{
    double lg = lgamma(a);
    if (x <= 0)
        return 1;
    if (x < a + 1) {
        double ap = a, sum = 1 / a, del = sum;
        for (int n = 0; n < 1000 && fabs(del) > fabs(sum) * 1e-15; n++)
            sum += del *= x / ++ap;
        return 1 - sum * exp(-x + a * log(x) - lg);
    }
    double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
    for (int i = 1; i < 1000; i++) {
        double an = -i * (i - a), del;
        b += 2;
        d = an * d + b;
        c = b + an / c;
        d = 1 / (fabs(d) < 1e-300 ? 1e-300 : d);
        del = d * c;
        h *= del;
        if (fabs(del - 1) < 1e-15)
            break;
    }
    return exp(-x + a * log(x) - lg) * h;
}

static int cmp_by_expected(const void *a, const void *b)
{
    const double *x = a, *y = b;
    return (x[1] > y[1]) - (x[1] < y[1]);
}

/* Pearson chi-square p-value of observed against expected counts; cells expected below 5
 * are pooled into one (Mitsuba 3's chi2 test does the same). */
static double chi2_pvalue(const double *obs, const double *expct, int n)
{
    double (*cell)[2] = util_malloc(sizeof *cell * (size_t)n);
    double pool_o = 0, pool_e = 0, chi2 = 0;
    int cells = 0, i = 0;
    for (int k = 0; k < n; k++)
        cell[k][0] = obs[k], cell[k][1] = expct[k];
    qsort(cell, (size_t)n, sizeof *cell, cmp_by_expected);
    for (; i < n && (cell[i][1] < 5 || pool_e < 5); i++)
        pool_o += cell[i][0], pool_e += cell[i][1];
    if (pool_e > 0 || pool_o > 0) {
        if (pool_e <= 0) {
            free(cell);
            return 0; /* samples where the pdf says none can be */
        }
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        cells++;
    }
    for (; i < n; i++, cells++)
        chi2 += (cell[i][0] - cell[i][1]) * (cell[i][0] - cell[i][1]) / cell[i][1];
    free(cell);
    return cells < 2 ? 1 : gamma_q(0.5 * (cells - 1), 0.5 * chi2);
}

/* Sidak: per-test level so the whole family rejects a correct sampler with probability 0.01. */
static double sidak(int tests) { return 1 - pow(1 - 0.01, 1.0 / tests); }

/* ---- measuring one (setting, wo) --------------------------------------------------------- */

/* The sphere in 10 x 20 equal-area bins (cos theta, phi), as pbrt-v4's chi2 test. Each bin
 * is integrated by cells uniform in theta (so lobes at the poles stay resolved; the two
 * polar bins get 4x more, for the narrow refracted lobes of glass seen head-on) and phi,
 * with 2 x 2 Gauss-Legendre nodes per cell (exact for cubics). Half-vector lobes seen at
 * grazing angles are slivers about 2 alpha cos(theta_o) wide in phi, as narrow as a cell at
 * 75 degrees for alpha 0.04: where the pdf's second differences over the nodes say a cell's
 * quadrature may be off by more than REFINE_ERR expected samples, that cell and its four
 * edge neighbours are integrated again on a REFINE x REFINE grid of their own (measure_case).
 * The quadrature checks stop at 75 degrees; sampled albedos cover the rest. */
#define BT 10
#define BP 20
#define GT 16
#define GP 8
#define NBINS (BT * BP)
#define NTH (2 * GT * (BT + 6)) /* theta nodes */
#define NPH (BP * GP * 2)       /* phi nodes */
#define NGRID (NTH * NPH)
#define NSAMPLES 100000
#define NTC (NTH / 2) /* theta cells */
#define NPC (NPH / 2) /* phi cells */
#define REFINE 4
#define REFINE_ERR 0.5

typedef struct measure {
    double expected[NBINS + 1];  /* N * integral of pdf per bin; [NBINS]: the rest */
    double observed[NBINS + 1];  /* sample counts; [NBINS]: failed or Dirac samples */
    double pdf_integral;         /* integral of pdf over the sphere */
    double albedo_quad[3];       /* integral of f |cos| (non-Dirac parts), by quadrature */
    double albedo_mc[3];         /* mean sample weight, all parts */
    double albedo_mc_smooth[3];  /* mean weight of the non-Dirac samples (times 1 or 0) */
    double sigma_mc[3];          /* standard errors of albedo_mc */
    double sigma_smooth[3];
    double valid_smooth;         /* fraction of samples that are non-Dirac directions */
    int bad_samples;             /* samples whose weight != f cos / pdf or pdf != pdf(wi) */
    int nonfinite;
} measure;

static int bin_of(vec3 w)
{
    double phi = atan2(w.y, w.x);
    int t = (int)floor((w.z + 1.0) / 2.0 * BT), p;
    if (phi < 0)
        phi += 2 * PI;
    p = (int)floor(phi / (2 * PI) * BP);
    t = t < 0 ? 0 : t >= BT ? BT - 1 : t;
    p = p < 0 ? 0 : p >= BP ? BP - 1 : p;
    return t * BP + p;
}

static vec3 grid_dir[NGRID];
static double grid_weight[NGRID]; /* solid angle of each node */
static int grid_bin[NGRID];
static double cell_th_lo[NTC], cell_dth[NTC]; /* theta cell k: [lo, lo + dth] */
static int cell_bin_t[NTC];

static void grid_init(void)
{
    const double g = 0.5 / sqrt(3.0);
    int n = 0, k = 0;
    qbuf = util_malloc(sizeof *qbuf * CHUNK);
    rbuf = util_malloc(sizeof *rbuf * CHUNK);
    for (int bin = 0; bin < BT; bin++) {
        int cells = bin == 0 || bin == BT - 1 ? 4 * GT : GT;
        double th_lo = acos(-1 + 2.0 * (bin + 1) / BT), th_hi = acos(-1 + 2.0 * bin / BT);
        double dth = (th_hi - th_lo) / cells;
        for (int c = 0; c < cells; c++) {
            cell_th_lo[n / 2 + c] = th_lo + c * dth;
            cell_dth[n / 2 + c] = dth;
            cell_bin_t[n / 2 + c] = bin;
        }
        for (int c = 0; c < 2 * cells; c++, n++) {
            double th = th_lo + (c / 2 + 0.5 + (c % 2 ? g : -g)) * dth;
            for (int p = 0; p < NPH; p++, k++) {
                grid_dir[k] = polar(th, (p / 2 + 0.5 + (p % 2 ? g : -g)) * 2 * PI / (BP * GP));
                grid_weight[k] = 0.5 * dth * sin(th) * PI / (BP * GP);
                grid_bin[k] = bin * BP + p / (2 * GP);
            }
        }
    }
}

/* One quadrature node's share of pdf and f |cos|, counted in m (sign -1: taken back). */
static void add_node(measure *m, const BrdfQuery *q, const BrdfResult *r, double w, int bin, double pdf_scale,
                     double f_scale, double sign)
{
    double pdf = r->pdf * pdf_scale, cosw = fabs(q->wi.z) * w * f_scale * sign;
    m->nonfinite += sign > 0 && (!finite3(r->f) || !isfinite(r->pdf));
    m->expected[bin] += sign * pdf * w * NSAMPLES;
    m->pdf_integral += sign * pdf * w;
    m->albedo_quad[0] += r->f.x * cosw;
    m->albedo_quad[1] += r->f.y * cosw;
    m->albedo_quad[2] += r->f.z * cosw;
}

/* The grid's nodes' queries and results (grid_pdf: their pdfs), kept for the refinement. */
static BrdfQuery *grid_q;
static BrdfResult *grid_r;
static uint8_t cell_refine[NTC * NPC];

/* Cells whose quadrature may be off by REFINE_ERR expected samples or more: a node's second
 * difference of the pdf (in theta or phi, whichever is larger) times the cell's solid angle
 * estimates the error of a rule exact for cubics where the pdf is smooth at the nodes'
 * scale, and is large where it is not (a lobe between nodes); the theta nodes' uneven
 * spacing makes it count a slope too, which only refines more. Marked with their edge
 * neighbours. */
static int mark_cells(double pdf_scale)
{
    static uint8_t rough[NTC * NPC];
    memset(rough, 0, sizeof rough);
    for (int tc = 0; tc < NTC; tc++)
        for (int pc = 0; pc < NPC; pc++) {
            double d2 = 0, area = 0;
            for (int a = 0; a < 4; a++) {
                int n = 2 * tc + a / 2, p = 2 * pc + a % 2;
                double v = grid_r[n * NPH + p].pdf;
                double vp = grid_r[n * NPH + (p + 1) % NPH].pdf, vm = grid_r[n * NPH + (p + NPH - 1) % NPH].pdf;
                d2 = fmax(d2, fabs(vp - 2 * v + vm));
                if (n > 0 && n + 1 < NTH)
                    d2 = fmax(d2, fabs(grid_r[(n + 1) * NPH + p].pdf - 2 * v + grid_r[(n - 1) * NPH + p].pdf));
                area += grid_weight[n * NPH + p];
            }
            rough[tc * NPC + pc] = d2 * pdf_scale * area * NSAMPLES > REFINE_ERR;
        }
    int marked = 0;
    for (int tc = 0; tc < NTC; tc++)
        for (int pc = 0; pc < NPC; pc++) {
            bool any = rough[tc * NPC + pc] || rough[tc * NPC + (pc + 1) % NPC] ||
                       rough[tc * NPC + (pc + NPC - 1) % NPC] || (tc > 0 && rough[(tc - 1) * NPC + pc]) ||
                       (tc + 1 < NTC && rough[(tc + 1) * NPC + pc]);
            cell_refine[tc * NPC + pc] = any;
            marked += any;
        }
    return marked;
}

/* The marked cells again, REFINE x REFINE sub-cells of 2 x 2 Gauss nodes each, in place of
 * their four nodes. */
static void refine_cells(const brdf_setting *s, vec3 wo, double pdf_scale, double f_scale, measure *m)
{
    const double g = 0.5 / sqrt(3.0), dph = 2 * PI / NPC;
    enum { PER_CELL = 4 * REFINE * REFINE };
    BrdfQuery q0 = query(s, BRDF_OP_EVAL, wo, v3(0, 0, 1), v3(0, 0, 0));
    static double w[CHUNK];
    static int bin[CHUNK];
    int n = 0;
    for (int c = 0; c <= NTC * NPC; c++) {
        if (c == NTC * NPC || n + PER_CELL > CHUNK) {
            brdf_runner_run(&runner, qbuf, rbuf, (size_t)n);
            for (int i = 0; i < n; i++)
                add_node(m, &qbuf[i], &rbuf[i], w[i], bin[i], pdf_scale, f_scale, 1);
            n = 0;
        }
        if (c == NTC * NPC || !cell_refine[c])
            continue;
        int tc = c / NPC, pc = c % NPC;
        for (int a = 0; a < 4; a++) {
            int k = (2 * tc + a / 2) * NPH + 2 * pc + a % 2;
            add_node(m, &grid_q[k], &grid_r[k], grid_weight[k], grid_bin[k], pdf_scale, f_scale, -1);
        }
        double dth = cell_dth[tc] / REFINE, dp = dph / REFINE;
        for (int i = 0; i < 2 * REFINE; i++)
            for (int j = 0; j < 2 * REFINE; j++, n++) {
                double th = cell_th_lo[tc] + (i / 2 + 0.5 + (i % 2 ? g : -g)) * dth;
                double ph = pc * dph + (j / 2 + 0.5 + (j % 2 ? g : -g)) * dp;
                qbuf[n] = q0;
                qbuf[n].wi = polar(th, ph);
                w[n] = 0.25 * dth * dp * sin(th);
                bin[n] = cell_bin_t[tc] * BP + pc / GP;
            }
    }
}

/* Quadrature over the grid (when `grid`; refined where the pdf is narrower than its
 * cells) and NSAMPLES samples of one (setting, wo). pdf_scale and f_scale break the
 * measurement on purpose (the self-test). */
static void measure_case(const brdf_setting *s, vec3 wo, bool grid, double pdf_scale, double f_scale, measure *m)
{
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    memset(m, 0, sizeof *m);
    if (grid && !grid_q) {
        grid_q = util_malloc(NGRID * sizeof *grid_q);
        grid_r = util_malloc(NGRID * sizeof *grid_r);
    }
    for (int k0 = 0; grid && k0 < NGRID; k0 += CHUNK) {
        int n = NGRID - k0 < CHUNK ? NGRID - k0 : CHUNK;
        BrdfQuery q0 = query(s, BRDF_OP_EVAL, wo, v3(0, 0, 1), v3(0, 0, 0));
        for (int i = 0; i < n; i++) {
            grid_q[k0 + i] = q0;
            grid_q[k0 + i].wi = grid_dir[k0 + i];
        }
        brdf_runner_run(&runner, grid_q + k0, grid_r + k0, (size_t)n);
        for (int i = 0; i < n; i++)
            add_node(m, &grid_q[k0 + i], &grid_r[k0 + i], grid_weight[k0 + i], grid_bin[k0 + i], pdf_scale,
                     f_scale, 1);
    }
    if (grid && mark_cells(pdf_scale) > 0)
        refine_cells(s, wo, pdf_scale, f_scale, m);
    m->expected[NBINS] = fmax(0, NSAMPLES * (1 - m->pdf_integral));
    double sq[3] = {0}, sq_smooth[3] = {0};
    for (int i0 = 0; i0 < NSAMPLES; i0 += CHUNK) {
        int n = NSAMPLES - i0 < CHUNK ? NSAMPLES - i0 : CHUNK;
        for (int i = 0; i < n; i++)
            q[i] = query(s, BRDF_OP_SAMPLE, wo, v3(0, 0, 1), rnd_u());
        brdf_runner_run(&runner, q, r, (size_t)n);
        for (int i = 0; i < n; i++) {
            const BrdfResult *x = &r[i];
            double w[3] = {x->s_weight.x, x->s_weight.y, x->s_weight.z};
            bool delta = (x->s_flags & BRDF_FLAG_DELTA) != 0, smooth = x->s_flags && !delta;
            if (!finite3(x->s_weight) || !finite3(x->s_wi) || !isfinite(x->s_pdf)) {
                m->nonfinite++;
                continue;
            }
            if (smooth) {
                double cosw = fabs(x->s_wi.z) / x->s_pdf_eval;
                double fw[3] = {x->s_f.x * cosw, x->s_f.y * cosw, x->s_f.z * cosw};
                for (int c = 0; c < 3; c++)
                    if (fabs(w[c] - fw[c]) > 1e-4 * fabs(fw[c]) + 1e-6)
                        m->bad_samples++;
                if (fabs(x->s_pdf - x->s_pdf_eval) > 1e-4 * x->s_pdf_eval)
                    m->bad_samples++;
                m->observed[bin_of(x->s_wi)]++;
                m->valid_smooth += 1.0 / NSAMPLES;
            } else {
                m->observed[NBINS]++;
            }
            for (int c = 0; c < 3; c++) {
                w[c] *= f_scale;
                m->albedo_mc[c] += w[c] / NSAMPLES;
                sq[c] += w[c] * w[c] / NSAMPLES;
                if (smooth) {
                    m->albedo_mc_smooth[c] += w[c] / NSAMPLES;
                    sq_smooth[c] += w[c] * w[c] / NSAMPLES;
                }
            }
        }
    }
    for (int c = 0; c < 3; c++) {
        m->sigma_mc[c] = sqrt(fmax(0, sq[c] - m->albedo_mc[c] * m->albedo_mc[c]) / NSAMPLES);
        m->sigma_smooth[c] = sqrt(fmax(0, sq_smooth[c] - m->albedo_mc_smooth[c] * m->albedo_mc_smooth[c]) / NSAMPLES);
    }
}

/* Does the setting have any non-Dirac part to test against its pdf? */
static bool has_smooth_part(const measure *m) { return m->pdf_integral > 1e-3; }

/* The chi-square verdict and the pdf-normalisation checks for one case; false with the
 * reason in why. */
static bool check_sampling(const measure *m, double alpha, char *why, size_t cap)
{
    double p = chi2_pvalue(m->observed, m->expected, NBINS + 1);
    double tol = 5 * sqrt(fmax(m->valid_smooth * (1 - m->valid_smooth), 1e-4) / NSAMPLES) + 2e-3;
    if (p < alpha) {
        int worst = 0;
        for (int i = 1; i <= NBINS; i++)
            if (fabs(m->observed[i] - m->expected[i]) / sqrt(m->expected[i] + 1) >
                fabs(m->observed[worst] - m->expected[worst]) / sqrt(m->expected[worst] + 1))
                worst = i;
        if (worst == NBINS)
            return snprintf(why, cap, "chi2 p-value %.3g < %.3g; worst cell: failed/Dirac samples %g, expected %.1f",
                            p, alpha, m->observed[worst], m->expected[worst]), false;
        return snprintf(why, cap, "chi2 p-value %.3g < %.3g; worst cell: cos theta bin %d, phi bin %d: observed %g, "
                        "expected %.1f", p, alpha, worst / BP, worst % BP, m->observed[worst], m->expected[worst]), false;
    }
    /* The pdf integrates to the probability that sample() returns a non-Dirac direction:
     * 1 where it never fails or picks a Dirac lobe. */
    if (m->pdf_integral > 1 + 2e-3)
        return snprintf(why, cap, "pdf integrates to %.4f > 1", m->pdf_integral), false;
    if (fabs(m->pdf_integral - m->valid_smooth) > tol)
        return snprintf(why, cap, "pdf integrates to %.4f but %.4f of samples are non-Dirac directions",
                        m->pdf_integral, m->valid_smooth), false;
    return true;
}

/* Energy: albedo <= 1 by quadrature of eval (plus the Dirac parts' mean weight) and by the
 * sample mean; and sample() agrees with eval/pdf: the mean weight of its non-Dirac samples
 * equals the quadrature of f cos. False with the reason in why. */
static bool check_energy(const measure *m, bool quadrature, char *why, size_t cap)
{
    for (int c = 0; c < 3 && !quadrature; c++)
        if (m->albedo_mc[c] > 1 + 1e-3 + 5 * m->sigma_mc[c])
            return snprintf(why, cap, "channel %d: albedo %.4f +- %.4f > 1 (sampled)", c, m->albedo_mc[c],
                            m->sigma_mc[c]), false;
    for (int c = 0; c < 3 && quadrature; c++) {
        double delta = m->albedo_mc[c] - m->albedo_mc_smooth[c];
        double total = m->albedo_quad[c] + delta;
        double diff = m->albedo_mc_smooth[c] - m->albedo_quad[c];
        if (total > 1 + 5e-3 + 5 * m->sigma_mc[c])
            return snprintf(why, cap, "channel %d: albedo %.4f > 1 (quadrature)", c, total), false;
        if (m->albedo_mc[c] > 1 + 1e-3 + 5 * m->sigma_mc[c])
            return snprintf(why, cap, "channel %d: albedo %.4f +- %.4f > 1 (sampled)", c, m->albedo_mc[c],
                            m->sigma_mc[c]), false;
        if (fabs(diff) > 5 * m->sigma_smooth[c] + 5e-3 * m->albedo_quad[c] + 1e-3)
            return snprintf(why, cap, "channel %d: mean sample weight %.4f +- %.4f != integral of f cos %.4f", c,
                            m->albedo_mc_smooth[c], m->sigma_smooth[c], m->albedo_quad[c]), false;
    }
    return true;
}

/* ---- the tests -------------------------------------------------------------------------- */

/* Model table and parameter parsing: clear errors for bad names and values. */
TEST(brdf, model_table)
{
    brdf_setting s;
    for (int i = 0; i < brdf_num_models; i++)
        CHECK(brdf_model_find(brdf_models[i].name) == &brdf_models[i]);
    CHECK(brdf_model_find("blinn") == NULL);
    CHECK(brdf_model_find("") == NULL);
    brdf_setting_init(&s, brdf_model_find("phong"));
    CHECK(s.v[BRDF_SLOT_PARAMS + BRDF_P_SHAPE] == 32);
    CHECK(brdf_setting_set(&s, "exponent", "64") && s.v[BRDF_SLOT_PARAMS + BRDF_P_SHAPE] == 64);
    CHECK(brdf_setting_set(&s, "diffuse", "0.5") && s.v[0] == 0.5f && s.v[1] == 0.5f && s.v[2] == 0.5f);
    CHECK(brdf_setting_set(&s, "diffuse", "0.1,0.2,0.3") && s.v[0] == 0.1f && s.v[2] == 0.3f);
    CHECK(!brdf_setting_set(&s, "alpha", "0.1"));        /* not a Phong parameter */
    CHECK(!brdf_setting_set(&s, "exponent", "abc"));
    CHECK(!brdf_setting_set(&s, "exponent", "-1"));      /* out of range */
    CHECK(!brdf_setting_set(&s, "exponent", "1,2,3"));   /* scalar */
    CHECK(!brdf_setting_set(&s, "diffuse", "0.1,0.2"));  /* two components */
    CHECK(!brdf_setting_set(&s, "diffuse", "0.1,0.2,0.3,0.4"));
    CHECK(!brdf_setting_set(&s, "diffuse", "0.1,,0.3"));
    CHECK(!brdf_setting_set(&s, "diffuse", "nan"));
    CHECK(!brdf_setting_set(&s, "diffuse", "1.5"));
    CHECK(s.v[0] == 0.1f && s.v[BRDF_SLOT_PARAMS + BRDF_P_SHAPE] == 64); /* failures change nothing */
    brdf_setting_init(&s, brdf_model_find("gltf"));
    CHECK(brdf_setting_set(&s, "transmission", "0.5") && s.m.transmission == 0.5f);
    CHECK(brdf_setting_set(&s, "specular-color", "1,0.5,0.25") && s.m.specular_color.z == 0.25f);
    for (int i = 0; i < num_cases(); i++)
        CHECKF(make_setting(&cases[i], &s), "config %s", describe(&cases[i]));
    /* the table: ids unique and glTF's the special one; every model tested (num_cases) */
    for (int i = 0; i < brdf_num_models; i++) {
        for (int k = 0; k < i; k++)
            CHECKF(brdf_models[k].id != brdf_models[i].id, "models %s and %s share id %u", brdf_models[k].name,
                   brdf_models[i].name, brdf_models[i].id);
        CHECKF(brdf_models[i].num_params > 0 && brdf_models[i].num_params <= BRDF_MAX_PARAMS, "%s: %d parameters",
               brdf_models[i].name, brdf_models[i].num_params);
        CHECKF((brdf_models[i].id == BRDF_GLTF) == !strcmp(brdf_models[i].name, "gltf"), "%s: id %u",
               brdf_models[i].name, brdf_models[i].id);
    }
    CHECK(num_cases() < (int)(sizeof cases / sizeof *cases)); /* (full: a model may be left out) */
}

/* No NaN or Inf anywhere, f >= 0, pdf >= 0, weight >= 0, sampled directions unit length,
 * and nothing from an opaque model below its surface: over random, grazing (|z| down to
 * 1e-8 and 0), normal, back-facing and degenerate (wi = +-wo) directions and edge randoms. */
TEST(brdf, finite_and_positive)
{
    enum { N = 8192 };
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    rng_state = 1;
    for (int ci = 0; ci < num_cases(); ci++) {
        brdf_setting s;
        int bad = 0, below = 0;
        make_setting(&cases[ci], &s);
        for (int i = 0; i < N; i++) {
            vec3 wo = polar(acos(1 - 2 * rnd()), 2 * PI * rnd()), wi = polar(acos(1 - 2 * rnd()), 2 * PI * rnd());
            vec3 u = rnd_u();
            double g = pow(10.0, -2.0 - 6.0 * rnd()) * (rnd() < 0.5 ? -1 : 1);
            switch (i % 8) {
            case 1: wo = polar(acos(g), 2 * PI * rnd()); break;     /* grazing wo */
            case 2: wi = polar(acos(g), 2 * PI * rnd()); break;     /* grazing wi */
            case 3: wo = polar(PI / 2, 2 * PI * rnd()); wo.z = 0; wi = v3(-wo.x, -wo.y, 0); break; /* z = 0 */
            case 4: wi = wo; break;
            case 5: wi = v3(-wo.x, -wo.y, -wo.z); break;
            case 6: wo = v3(0, 0, i & 8 ? 1 : -1); wi = v3(-wi.x, -wi.y, wi.z); break;
            case 7: u = v3(i & 8 ? 0 : 0.99999994, i & 16 ? 0 : 0.99999994, i & 32 ? 0 : 0.99999994); break;
            }
            q[i] = query(&s, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
        }
        brdf_runner_run(&runner, q, r, N);
        for (int i = 0; i < N; i++) {
            const BrdfResult *x = &r[i];
            bool ok = finite3(x->f) && isfinite(x->pdf) && finite3(x->s_wi) && finite3(x->s_weight) &&
                      isfinite(x->s_pdf) && finite3(x->s_f) && isfinite(x->s_pdf_eval);
            ok = ok && x->f.x >= 0 && x->f.y >= 0 && x->f.z >= 0 && x->pdf >= 0 && x->s_pdf >= 0;
            ok = ok && x->s_weight.x >= 0 && x->s_weight.y >= 0 && x->s_weight.z >= 0;
            if (x->s_flags) {
                double len = sqrt(sum3((vec3){x->s_wi.x * x->s_wi.x, x->s_wi.y * x->s_wi.y, x->s_wi.z * x->s_wi.z}));
                ok = ok && fabs(len - 1) < 1e-4 && x->s_pdf > 0;
            } else {
                ok = ok && sum3(x->s_weight) == 0;
            }
            if (!ok && bad++ < 3)
                fprintf(stderr, "  %s: wo (%g %g %g) wi (%g %g %g) u (%g %g %g): f %g pdf %g s_wi (%g %g %g) "
                        "w %g pdf %g flags %u\n", describe(&cases[ci]), q[i].wo.x, q[i].wo.y, q[i].wo.z,
                        q[i].wi.x, q[i].wi.y, q[i].wi.z, q[i].u.x, q[i].u.y, q[i].u.z, x->f.x, x->pdf,
                        x->s_wi.x, x->s_wi.y, x->s_wi.z, x->s_weight.x, x->s_pdf, x->s_flags);
            if (!brdf_setting_two_sided(&s) && (q[i].wo.z <= 0 || q[i].wi.z <= 0) && (sum3(x->f) != 0 || x->pdf != 0))
                below++;
            if (!brdf_setting_two_sided(&s) && x->s_flags && (q[i].wo.z <= 0 || x->s_wi.z <= 0))
                below++;
        }
        CHECKF(bad == 0, "%s: %d queries with NaN/Inf or negative values", describe(&cases[ci]), bad);
        CHECKF(below == 0, "%s: %d queries reflect light below an opaque surface", describe(&cases[ci]), below);
    }
    close_runner();
}

/* The kernel specialised on a query's features (brdf_query_features, as the renderer's
 * kernels are on a scene's) computes what the unspecialised one does, bit for bit, for
 * every setting: over the same random, grazing and degenerate directions as above, eval,
 * sample and the NDF queries. A feature missing from brdf_query_features would compile code out from under
 * the tests that follow (they run the specialised kernel); this finds it. */
TEST(brdf, specialised_same)
{
    enum { N = 4096 };
    static BrdfResult unspec[N];
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    rng_state = 10;
    for (int ci = 0; ci < num_cases(); ci++) {
        brdf_setting s;
        int differ = 0;
        make_setting(&cases[ci], &s);
        for (int i = 0; i < N; i++) {
            vec3 wo = polar(acos(1 - 2 * rnd()), 2 * PI * rnd()), wi = polar(acos(1 - 2 * rnd()), 2 * PI * rnd());
            if (i % 4 == 1)
                wo = polar(acos(pow(10.0, -2.0 - 6.0 * rnd())), 2 * PI * rnd()); /* grazing */
            if (i % 4 == 2)
                wi = wo;
            q[i] = query(&s, i % 8 == 7 ? BRDF_OP_NDF : BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, rnd_u());
        }
        runner.all_features = true;
        brdf_runner_run(&runner, q, unspec, N);
        runner.all_features = false;
        brdf_runner_run(&runner, q, r, N);
        for (int i = 0; i < N; i++) {
            const float *a = &r[i].f.x, *b = &unspec[i].f.x;
            bool same = !memcmp(&r[i].pdf, &unspec[i].pdf, sizeof(float)) &&
                        !memcmp(&r[i].s_pdf, &unspec[i].s_pdf, sizeof(float)) &&
                        !memcmp(&r[i].s_pdf_eval, &unspec[i].s_pdf_eval, sizeof(float)) &&
                        r[i].s_flags == unspec[i].s_flags;
            for (int c = 0; c < 3; c++)
                same = same && !memcmp(&a[c], &b[c], sizeof(float)) &&
                       !memcmp(&(&r[i].s_wi.x)[c], &(&unspec[i].s_wi.x)[c], sizeof(float)) &&
                       !memcmp(&(&r[i].s_weight.x)[c], &(&unspec[i].s_weight.x)[c], sizeof(float)) &&
                       !memcmp(&(&r[i].s_f.x)[c], &(&unspec[i].s_f.x)[c], sizeof(float));
            if (!same && differ++ < 2)
                fprintf(stderr, "  %s (features 0x%016llx): query %d: f %g pdf %g w %g flags %u, unspecialised f %g pdf %g "
                        "w %g flags %u\n", describe(&cases[ci]), (unsigned long long)brdf_query_features(&q[i]), i, a[0], r[i].pdf,
                        r[i].s_weight.x, r[i].s_flags, b[0], unspec[i].pdf, unspec[i].s_weight.x, unspec[i].s_flags);
        }
        CHECKF(differ == 0, "%s: %d of %d queries differ from the unspecialised kernel's", describe(&cases[ci]), differ, N);
    }
    close_runner();
}

/* Helmholtz reciprocity f(wo, wi) = f(wi, wo) for every reflection; refraction instead obeys
 * f(wo, wi) / eta(wi)^2 = f(wi, wo) / eta(wo)^2 (eta of the side each direction is on),
 * because the transmitted solid angle is compressed by (eta_t / eta_i)^2. */
TEST(brdf, reciprocity)
{
    enum { N = 4096 };
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    rng_state = 2;
    for (int ci = 0; ci < num_cases(); ci++) {
        brdf_setting s;
        int bad = 0, nonzero = 0;
        make_setting(&cases[ci], &s);
        bool sides = brdf_setting_two_sided(&s);
        /* (a diffuse transmission is reciprocal as it is: no index changes across it) */
        bool refracts = s.model->id == BRDF_DIELECTRIC || s.m.transmission > 0;
        double ior = s.model->id == BRDF_DIELECTRIC ? s.v[BRDF_SLOT_PARAMS + BRDF_P_DIELECTRIC_IOR]
                                                     : s.m.ior;
        for (int i = 0; i < N; i++) {
            double zo = rnd(), zi = rnd();
            if (sides && i % 4 == 1)
                zi = -zi; /* refraction */
            if (sides && i % 4 == 2)
                zo = -zo, zi = -zi; /* reflection inside */
            if (sides && i % 4 == 3)
                zo = -zo;
            vec3 wo = polar(acos(zo), 2 * PI * rnd()), wi = polar(acos(zi), 2 * PI * rnd());
            q[2 * i] = query(&s, BRDF_OP_EVAL, wo, wi, v3(0, 0, 0));
            q[2 * i + 1] = query(&s, BRDF_OP_EVAL, wi, wo, v3(0, 0, 0));
        }
        brdf_runner_run(&runner, q, r, 2 * N);
        for (int i = 0; i < N; i++) {
            double scale = 1; /* f(wo, wi) / f(wi, wo) predicted */
            vec3 o = q[2 * i].wo, w = q[2 * i].wi;
            if (o.z * w.z < 0 && refracts) {
                /* Within ~3 degrees of grazing on the microfacet (its refracted side at the
                 * critical angle) 1 - F has an infinite slope and float directions cannot
                 * fix it to better than 10%: skip those pairs. */
                double e = w.z < 0 ? ior : 1 / ior, h[3] = {e * w.x + o.x, e * w.y + o.y, e * w.z + o.z};
                double len = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
                if (fabs(h[0] * o.x + h[1] * o.y + h[2] * o.z) < 0.05 * len ||
                    fabs(h[0] * w.x + h[1] * w.y + h[2] * w.z) < 0.05 * len)
                    continue;
                scale = w.z < 0 ? ior * ior : 1 / (ior * ior);
            }
            const float *a = &r[2 * i].f.x, *b = &r[2 * i + 1].f.x;
            for (int c = 0; c < 3; c++) {
                double x = a[c], y = b[c] * scale;
                nonzero += x > 0;
                if (fabs(x - y) > 2e-4 * fmax(x, y) + 1e-7 && bad++ < 3)
                    fprintf(stderr, "  %s: f(wo,wi) = %g, f(wi,wo) * %g = %g (wo %.9g %.9g %.9g wi %.9g %.9g %.9g)\n",
                            describe(&cases[ci]), x, scale, y, q[2 * i].wo.x, q[2 * i].wo.y, q[2 * i].wo.z, q[2 * i].wi.x, q[2 * i].wi.y, q[2 * i].wi.z);
            }
        }
        CHECKF(bad == 0, "%s: %d pairs break reciprocity", describe(&cases[ci]), bad);
        /* Dirac-only models have nothing to compare; the rest must have been exercised. */
        bool dirac = !strcmp(s.model->name, "mirror") ||
                     (s.model->id == BRDF_CONDUCTOR && s.v[BRDF_SLOT_PARAMS + BRDF_P_ALPHA] == 0) ||
                     (s.model->id == BRDF_DIELECTRIC && s.v[BRDF_SLOT_PARAMS + BRDF_P_DIELECTRIC_ALPHA] == 0) ||
                     (s.model->id == BRDF_GLTF && s.m.roughness == 0 && s.m.transmission == 1 &&
                      s.m.clearcoat_roughness == 0 && sum3(s.m.sheen_color) == 0); /* smooth glass, smooth coat */
        CHECKF(dirac || nonzero > N / 4, "%s: only %d non-zero values", describe(&cases[ci]), nonzero);
    }
    close_runner();
}

/* Lambert: the directional albedo equals the albedo at every angle, by quadrature of eval
 * and by uniform-sphere Monte Carlo (independent of sample()); and cosine sampling makes
 * every weight exactly the albedo. */
TEST(brdf, lambert_albedo)
{
    const double theta[] = {0, 30, 60, 85, 89.9};
    enum { N = CHUNK };
    brdf_setting s;
    const double kd[3] = {0.8, 0.5, 0.2};
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    make_setting(&configs[0], &s);
    rng_state = 3;
    for (int t = 0; t < 5; t++) {
        vec3 wo = polar(rad(theta[t]), 0.3);
        double mean[3] = {0}, sq[3] = {0};
        measure m;
        measure_case(&s, wo, true, 1, 1, &m);
        for (int i = 0; i < N; i++)
            q[i] = query(&s, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, polar(acos(1 - 2 * rnd()), 2 * PI * rnd()), rnd_u());
        brdf_runner_run(&runner, q, r, N);
        int bad_weight = 0;
        for (int i = 0; i < N; i++) {
            const float *f = &r[i].f.x, *w = &r[i].s_weight.x;
            for (int c = 0; c < 3; c++) {
                double e = f[c] * fabs(q[i].wi.z) * 4 * PI;
                mean[c] += e / N;
                sq[c] += e * e / N;
                bad_weight += fabs(w[c] - kd[c]) > 1e-5;
            }
        }
        for (int c = 0; c < 3; c++) {
            double sigma = sqrt((sq[c] - mean[c] * mean[c]) / N);
            CHECKF(fabs(mean[c] - kd[c]) < 4 * sigma, "theta %g: uniform MC albedo %.5f +- %.5f != %.2f", theta[t],
                   mean[c], sigma, kd[c]);
            CHECKF(fabs(m.albedo_quad[c] - kd[c]) < 1e-3, "theta %g: quadrature albedo %.5f != %.2f", theta[t],
                   m.albedo_quad[c], kd[c]);
        }
        CHECKF(bad_weight == 0, "theta %g: %d weights differ from the albedo", theta[t], bad_weight);
        CHECKF(fabs(m.pdf_integral - 1) < 1e-3, "theta %g: pdf integrates to %.5f", theta[t], m.pdf_integral);
    }
    close_runner();
}

/* The directions bsdf_sample draws follow bsdf_pdf (chi-square, Sidak-corrected 1% level
 * over all cases and angles of both tiers); pdf integrates to the fraction of non-Dirac
 * samples (1 where sampling never fails); each sample's weight and pdf equal f cos / pdf and
 * pdf at its wi; the mean weight equals the quadrature of f cos; and that albedo is <= 1
 * (energy conservation). Every (case, angle) is one measurement of NSAMPLES samples: the
 * fast tier has every case at one angle from outside (40 degrees) and, for the two-sided,
 * one from inside (110); the slow tier every angle (0, 40, 75, 110, 160). Each check's
 * level, and so its power, is what it was as one test. */
static const double sampling_theta[] = {0, 40, 75, 110, 160};
static void sampling_matches_pdf_at(bool slow_angles, unsigned seed)
{
    int tests = 0;
    if (!open_runner())
        return;
    for (int ci = 0; ci < num_cases(); ci++) {
        brdf_setting s;
        make_setting(&cases[ci], &s);
        tests += brdf_setting_two_sided(&s) ? 5 : 3;
    }
    rng_state = seed;
    for (int ci = 0; ci < num_cases(); ci++) {
        brdf_setting s;
        make_setting(&cases[ci], &s);
        for (int t = 0; t < (brdf_setting_two_sided(&s) ? 5 : 3); t++) {
            const double *theta = sampling_theta;
            const char *what = describe(&cases[ci]);
            char why[200];
            measure m;
            if (!slow_angles && t != 1 && t != 3)
                continue;
            measure_case(&s, polar(rad(theta[t]), 1.0), true, 1, 1, &m);
            CHECKF(m.nonfinite == 0, "%s wo %.0f: %d NaN/Inf", what, theta[t], m.nonfinite);
            CHECKF(m.bad_samples == 0, "%s wo %.0f: %d samples whose weight or pdf disagree with eval/pdf", what,
                   theta[t], m.bad_samples);
            if (has_smooth_part(&m) || m.valid_smooth > 0)
                CHECKF(check_sampling(&m, sidak(tests), why, sizeof why), "%s wo %.0f deg: %s", what, theta[t], why);
            CHECKF(check_energy(&m, true, why, sizeof why), "%s wo %.0f deg: %s", what, theta[t], why);
        }
    }
    close_runner();
}
TEST(brdf, sampling_matches_pdf) { sampling_matches_pdf_at(false, 4); }
/* The slow tier: every angle with the original test's stream (seed 4), that test exactly. */
TEST_SLOW(brdf, sampling_matches_pdf_more_angles) { sampling_matches_pdf_at(true, 4); }

/* A lobe as narrow as the grid's cells: the glTF lobe at metallic 0.3, roughness 0.2 (alpha
 * 0.04), seen at 75 degrees, with the stream (seed 14) of the run that found it. On the grid
 * alone its pdf integrated to 0.99823, so 177 samples below the horizon were expected where
 * the sampler (rightly) draws 340: the quadrature, refined where the pdf is narrow, gives
 * 0.99664, what a grid 16 times finer gives. */
TEST(brdf, sampling_narrow_grazing_lobe)
{
    brdf_setting s;
    measure m;
    char why[200];
    if (!open_runner())
        return;
    CHECK(make_setting(&(config){"gltf", "metallic=0.3 roughness=0.2 specular-color=1,0.5,0.5 ior=1.7"}, &s));
    rng_state = 14;
    measure_case(&s, polar(rad(75), 1.0), true, 1, 1, &m);
    CHECKF(mark_cells(1) > 0, "no cell refined");
    CHECKF(fabs(m.pdf_integral - 0.99664) < 2e-4, "pdf integrates to %.5f", m.pdf_integral);
    CHECKF(check_sampling(&m, 1e-3, why, sizeof why), "%s", why);
    CHECKF(check_energy(&m, true, why, sizeof why), "%s", why);
    close_runner();
}

/* Energy conservation from normal to grazing incidence (and from inside glass): the sampled
 * white-furnace albedo is <= 1 within its error. The fast tier has every case at 30 and
 * 89.9 degrees (and 135 from inside), the slow tier the other angles, each as before. */
static const double energy_theta[] = {0, 30, 60, 80, 85, 89, 89.9, 100, 135, 179};
static void energy_at(bool slow_angles, unsigned seed)
{
    if (!open_runner())
        return;
    rng_state = seed;
    for (int ci = 0; ci < num_cases(); ci++) {
        brdf_setting s;
        make_setting(&cases[ci], &s);
        for (int t = 0; t < (brdf_setting_two_sided(&s) ? 10 : 7); t++) {
            const double *theta = energy_theta;
            measure m;
            char why[200];
            if ((t == 1 || t == 6 || t == 8) == slow_angles)
                continue;
            measure_case(&s, polar(rad(theta[t]), 2.0), false, 1, 1, &m);
            CHECKF(m.nonfinite == 0, "%s wo %.1f: %d NaN/Inf", describe(&cases[ci]), theta[t], m.nonfinite);
            CHECKF(check_energy(&m, false, why, sizeof why), "%s wo %.1f deg: %s", describe(&cases[ci]), theta[t],
                   why);
        }
    }
    close_runner();
}
TEST(brdf, energy) { energy_at(false, 5); }
TEST_SLOW(brdf, energy_more_angles) { energy_at(true, 15); }

/* The checks have teeth: a pdf scaled by 1.1 fails the chi-square and the normalisation, and
 * a Lambert without its 1/pi (f scaled by pi) fails energy conservation and the agreement of
 * sample weights with eval. */
TEST(brdf, broken_variants_fail)
{
    brdf_setting s;
    measure m;
    if (!open_runner())
        return;
    rng_state = 6;
    make_setting(&configs[1], &s); /* white Lambert */
    char why[200] = "";
    measure_case(&s, polar(rad(30), 1.0), true, 1, 1, &m);
    CHECKF(check_sampling(&m, sidak(100), why, sizeof why), "the correct Lambert fails: %s", why);
    CHECKF(check_energy(&m, true, why, sizeof why), "the correct Lambert fails: %s", why);
    measure_case(&s, polar(rad(30), 1.0), true, 1.1, 1, &m);
    CHECKF(!check_sampling(&m, sidak(100), why, sizeof why), "a pdf scaled by 1.1 passed the sampling checks");
    printf("    pdf * 1.1 rejected: %s\n", why);
    measure_case(&s, polar(rad(30), 1.0), true, 1, PI, &m);
    CHECKF(!check_energy(&m, true, why, sizeof why), "a Lambert without 1/pi passed the energy checks");
    printf("    Lambert without 1/pi rejected: %s\n", why);
    close_runner();
}

/* ---- Fresnel -------------------------------------------------------------------------------- */

/* Fresnel's r_par, r_perp with complex cos_t: an independent conductor reference. */
static double fresnel_complex(double cos_i, double complex n)
{
    double sin2 = 1 - cos_i * cos_i;
    double complex cos_t = csqrt(1 - sin2 / (n * n));
    double complex rpar = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    double complex rperp = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    return 0.5 * (creal(rpar * conj(rpar)) + creal(rperp * conj(rperp)));
}

/* Dielectric Fresnel against analytic values: ((n-1)/(n+1))^2 at normal incidence, r_par = 0
 * at Brewster's angle, 1 at grazing and beyond the critical angle (total internal
 * reflection), equal transmission both ways through the interface (Stokes); conductors
 * against complex arithmetic and ((n-1)^2+k^2)/((n+1)^2+k^2); Schlick at its end points. */
TEST(brdf, fresnel)
{
    enum { N = 64 };
    BrdfQuery q[N];
    BrdfResult r[N];
    const double eta = 1.5, cn[3] = {0.143, 0.374, 1.442}, ck[3] = {3.983, 2.385, 1.603};
    double brewster = atan(eta), crit = asin(1 / eta);
    if (!open_runner())
        return;
    memset(q, 0, sizeof q);
    for (int i = 0; i < N; i++) {
        double c = i < 40 ? cos(rad(90.0 * i / 39)) : 0;
        q[i].op = BRDF_OP_FRESNEL;
        q[i].args = (vec4){(float)eta, 0.04f, 1, 0};
        q[i].material.base_color = (vec4){(float)cn[0], (float)cn[1], (float)cn[2], 1};
        q[i].material.brdf_params = (vec4){(float)ck[0], (float)ck[1], (float)ck[2], 0};
        q[i].wo.z = (float)c;
    }
    q[40].wo.z = (float)cos(brewster);
    q[41].wo.z = (float)-cos(crit + 0.01); /* inside, just past the critical angle */
    q[42].wo.z = (float)-cos(crit - 0.01);
    q[43].wo.z = (float)cos(rad(40));
    q[44].wo.z = (float)-sqrt(1 - sin(rad(40)) * sin(rad(40)) / (eta * eta)); /* the refracted ray of 43 */
    q[45].wo.z = 0.5f;
    q[45].material.base_color = (vec4){1.5f, 0.3f, 2, 1}; /* k = 0: a dielectric */
    q[45].material.brdf_params = (vec4){0, 0, 0, 0};
    brdf_runner_run(&runner, q, r, N);
    double f0 = pow((eta - 1) / (eta + 1), 2);
    CHECKF(fabs(r[0].f.x - f0) < 1e-6, "F(normal) %g != %g", r[0].f.x, f0);
    CHECKF(r[39].f.x > 0.999f, "F(grazing) %g", r[39].f.x);
    {
        double ci = cos(brewster), ct = cos(PI / 2 - brewster);
        double rperp = (ci - eta * ct) / (ci + eta * ct);
        CHECKF(fabs(r[40].f.x - 0.5 * rperp * rperp) < 1e-5, "Brewster: F %g != r_perp^2/2 %g", r[40].f.x,
               0.5 * rperp * rperp);
    }
    CHECKF(r[41].f.x == 1.0f, "past the critical angle F = %g, not 1 (TIR)", r[41].f.x);
    CHECKF(r[42].f.x < 1.0f, "before the critical angle F = %g", r[42].f.x);
    CHECKF(fabs(r[43].f.x - r[44].f.x) < 1e-5, "Stokes: F out %g != F in %g", r[43].f.x, r[44].f.x);
    for (int i = 0; i < 40; i++) {
        double c = q[i].wo.z, m5 = pow(1 - c, 5);
        CHECKF(fabs(r[i].f.y - (0.04 + 0.96 * m5)) < 1e-6, "Schlick at cos %g: %g", c, r[i].f.y);
        for (int ch = 0; ch < 3; ch++) {
            double ref = fresnel_complex(c, cn[ch] + ck[ch] * I);
            CHECKF(fabs((&r[i].s_f.x)[ch] - ref) < 2e-5, "conductor ch %d cos %g: %g != %g", ch, c,
                   (&r[i].s_f.x)[ch], ref);
            if (i == 0) {
                double n = cn[ch], k = ck[ch], normal = ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
                CHECKF(fabs((&r[i].s_f.x)[ch] - normal) < 1e-5, "conductor at normal incidence");
            }
        }
        /* The dielectric against the same complex formula with k = 0. */
        CHECKF(fabs(r[i].f.x - fresnel_complex(c, eta)) < 1e-5, "dielectric cos %g: %g", c, r[i].f.x);
    }
    CHECKF(fabs(r[45].s_f.y - fresnel_complex(0.5, 0.3)) < 1e-5, "conductor with k = 0, n < 1 (TIR side)");
    CHECKF(fabs(r[45].s_f.x - fresnel_complex(0.5, 1.5)) < 1e-5, "conductor with k = 0");
    close_runner();
}

/* Dirac lobes: the mirror returns r(wo) with weight R (Lo = R Li(r(wo)), docs/brdf.md); the
 * smooth dielectric reflects with probability F and refracts by Snell's law otherwise (always
 * reflecting past the critical angle); polished conductors and glTF weight by their Fresnel. */
TEST(brdf, delta_lobes)
{
    enum { N = 2000 };
    const double thetas[] = {0, 25, 50, 70, 85, 130, 150, 170};
    brdf_setting mirror, glass, gold, metal;
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    make_setting(&configs[2], &mirror);
    make_setting(&configs[18], &glass);
    make_setting(&configs[17], &gold);
    make_setting(&(config){"gltf", "metallic=1 roughness=0 base-color=0.9,0.6,0.2"}, &metal);
    for (int t = 0; t < 8; t++) {
        double th = rad(thetas[t]), ct = cos(th), eta = ct > 0 ? 1.5 : 1 / 1.5;
        vec3 wo = polar(th, 0.7), refl = v3(-wo.x, -wo.y, wo.z);
        double fr = fresnel_complex(fabs(ct), eta);
        double sin_t = sin(th) / eta;
        int nrefl = 0, bad = 0;
        if (sin_t >= 1)
            fr = 1;
        for (int i = 0; i < N; i++)
            q[i] = query(&glass, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, refl, v3((i + 0.5) / N, 0.5, 0.5));
        brdf_runner_run(&runner, q, r, N);
        for (int i = 0; i < N; i++) {
            const BrdfResult *x = &r[i];
            bad += x->f.x != 0 || x->pdf != 0; /* eval/pdf exclude the Dirac lobes */
            if (x->s_flags == (BRDF_FLAG_REFLECTION | BRDF_FLAG_DELTA)) {
                nrefl++;
                bad += fabs(x->s_wi.x - refl.x) + fabs(x->s_wi.y - refl.y) + fabs(x->s_wi.z - refl.z) > 1e-6;
                bad += fabs(x->s_weight.x - 1) > 1e-5;
            } else if (x->s_flags == (BRDF_FLAG_TRANSMISSION | BRDF_FLAG_DELTA)) {
                /* Snell: sin_t = sin_i / eta, the other side, in the plane of incidence */
                double st = sqrt(x->s_wi.x * x->s_wi.x + x->s_wi.y * x->s_wi.y);
                bad += fabs(st - sin_t) > 1e-5 || x->s_wi.z * wo.z >= 0;
                bad += fabs(x->s_wi.x * wo.y - x->s_wi.y * wo.x) > 1e-5 || x->s_wi.x * wo.x > 0;
                bad += fabs(x->s_weight.x - 1) > 1e-5;
            } else {
                bad++;
            }
        }
        CHECKF(bad == 0, "glass at %g deg: %d wrong samples", thetas[t], bad);
        CHECKF(fabs((double)nrefl / N - fr) <= 1.0 / N, "glass at %g deg: reflected %d/%d, F = %g", thetas[t], nrefl,
               N, fr);
        if (ct <= 0)
            continue;
        const brdf_setting *opaque[] = {&mirror, &gold, &metal};
        for (int k = 0; k < 3; k++)
            q[k] = query(opaque[k], BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, refl, v3(0.3, 0.6, 0.9));
        brdf_runner_run(&runner, q, r, 3);
        double m5 = pow(1 - ct, 5);
        const double want[3][3] = {
            {0.9, 0.6, 0.3},
            {fresnel_complex(ct, 0.143 + 3.983 * I), fresnel_complex(ct, 0.374 + 2.385 * I),
             fresnel_complex(ct, 1.442 + 1.603 * I)},
            {0.9 + 0.1 * m5, 0.6 + 0.4 * m5, 0.2 + 0.8 * m5}};
        for (int k = 0; k < 3; k++) {
            CHECKF(r[k].s_flags == (BRDF_FLAG_REFLECTION | BRDF_FLAG_DELTA), "model %d flags %u", k, r[k].s_flags);
            CHECKF(fabs(r[k].s_wi.x - refl.x) + fabs(r[k].s_wi.y - refl.y) + fabs(r[k].s_wi.z - refl.z) < 1e-6,
                   "model %d: not the mirror direction", k);
            CHECKF(r[k].f.x == 0 && r[k].pdf == 0, "model %d: eval/pdf of a Dirac lobe not 0", k);
            for (int c = 0; c < 3; c++)
                CHECKF(fabs((&r[k].s_weight.x)[c] - want[k][c]) < 2e-5, "model %d at %g deg ch %d: weight %g != %g",
                       k, thetas[t], c, (&r[k].s_weight.x)[c], want[k][c]);
        }
    }
    close_runner();
}

/* ---- the layers ------------------------------------------------------------------------------ */

/* A coat of weight 0, a black sheen, an iridescence of 0 and a diffuse transmission of 0 leave
 * the base exactly as it is: eval, pdf and sample give the same bits as the plain glTF
 * setting, whatever the layers' other parameters. */
TEST(brdf, layers_limit)
{
    enum { N = 8192 };
    static const char *bases[] = {"", "metallic=1 roughness=0.3 base-color=0.9,0.6,0.2", "roughness=0",
                                  "transmission=1 roughness=0.4", "transmission=0.5 metallic=0.2 roughness=0"};
    static const char *zero = "clearcoat=0 clearcoat-roughness=0.4 sheen-color=0 sheen-roughness=0.6 tilt=15 "
                              "iridescence=0 iridescence-ior=1.8 iridescence-thickness=300 diffuse-transmission=0 "
                              "diffuse-transmission-color=0.3,0.6,0.9";
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    rng_state = 7;
    for (int k = 0; k < (int)(sizeof bases / sizeof *bases); k++) {
        char with[512];
        brdf_setting base, layered;
        snprintf(with, sizeof with, "%s %s", bases[k], zero);
        make_setting(&(config){"gltf", bases[k]}, &base);
        make_setting(&(config){"gltf", with}, &layered);
        for (int i = 0; i < N / 2; i++) {
            vec3 wo = polar(acos(1 - 2 * rnd()), 2 * PI * rnd()), wi = polar(acos(1 - 2 * rnd()), 2 * PI * rnd());
            vec3 u = rnd_u();
            q[2 * i] = query(&base, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
            q[2 * i + 1] = query(&layered, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
        }
        brdf_runner_run(&runner, q, r, N);
        int differ = 0;
        for (int i = 0; i < N / 2; i++)
            differ += memcmp(&r[2 * i], &r[2 * i + 1], sizeof *r) != 0;
        CHECKF(differ == 0, "gltf %s: %d of %d queries differ with zero layers", bases[k], differ, N / 2);
    }
    close_runner();
}

/* The sheen's albedo table (glsl/lib/sheen_albedo.h) against an independent integral: Monte Carlo
 * over the hemisphere (uniform directions) of the README's Charlie D and Estevez & Kulla's
 * visibility, at points between the table's rows and columns. And the shader's sheen lobe
 * integrates to the table: quadrature of eval for a sheen over a black base at roughness
 * where E <= 1 everywhere (no normalisation), against the table's value. */
static double sheen_l(double x, double a)
{
    double t = (1 - a) * (1 - a);
    return (21.5473 + (25.3245 - 21.5473) * t) / (1 + (3.82987 + (3.32435 - 3.82987) * t) *
                                                         pow(x, 0.19823 + (0.16801 - 0.19823) * t)) +
           (-1.97760 + (-1.27393 + 1.97760) * t) * x + (-4.32054 + (-4.85967 + 4.32054) * t);
}

static double sheen_lambda(double c, double a)
{
    return c < 0.5 ? exp(sheen_l(c, a)) : exp(2 * sheen_l(0.5, a) - sheen_l(1 - c, a));
}

TEST(brdf, sheen_albedo)
{
    const double cs[] = {0.004, 0.03, 0.1, 0.35, 0.62, 0.93}, rs[] = {0.1, 0.27, 0.5, 0.81, 1};
    enum { M = 400000 };
    BrdfQuery q[30];
    BrdfResult r[30];
    int n = 0;
    if (!open_runner())
        return;
    memset(q, 0, sizeof q);
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 5; j++, n++) {
            q[n].op = BRDF_OP_FRESNEL;
            q[n].wo.z = (float)cs[i];
            q[n].args.w = (float)rs[j];
        }
    brdf_runner_run(&runner, q, r, (size_t)n);
    rng_state = 8;
    for (int k = 0; k < n; k++) {
        double mu = cs[k / 5], a = rs[k % 5] * rs[k % 5], so = sqrt(1 - mu * mu), sum = 0, sq = 0;
        for (int s = 0; s < M; s++) {
            double ci = rnd(), ph = 2 * PI * rnd(), si = sqrt(1 - ci * ci);
            double h[3] = {so + si * cos(ph), si * sin(ph), mu + ci};
            double s2 = (h[0] * h[0] + h[1] * h[1]) / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
            double d = (2 + 1 / a) * pow(s2, 0.5 / a) / (2 * PI);
            double e = ci < 0.001 ? 0 : 2 * PI * d * ci / ((1 + sheen_lambda(mu, a) + sheen_lambda(ci, a)) * 4 * mu * ci);
            sum += e / M;
            sq += e * e / M;
        }
        double sigma = sqrt((sq - sum * sum) / M);
        CHECKF(fabs(r[k].f.z - sum) < 4 * sigma + 0.02 * sum + 1e-3, "sheen E(cos %g, r %g): table %.4f, integral %.4f +- %.4f",
               cs[k / 5], rs[k % 5], r[k].f.z, sum, sigma);
    }
    for (int j = 2; j < 5; j++) {
        char params[128];
        brdf_setting s;
        snprintf(params, sizeof params, "base-color=0 specular=0 sheen-color=1 sheen-roughness=%g", rs[j]);
        make_setting(&(config){"gltf", params}, &s);
        for (int t = 0; t < 4; t++) {
            double th = rad(t * 25.0);
            measure m;
            BrdfQuery e = {.op = BRDF_OP_FRESNEL, .wo = {0, 0, (float)cos(th)}, .args = {0, 0, 0, (float)rs[j]}};
            BrdfResult er;
            brdf_runner_run(&runner, &e, &er, 1);
            measure_case(&s, polar(th, 0.4), true, 1, 1, &m);
            CHECKF(fabs(m.albedo_quad[0] - er.f.z) < 0.01 * er.f.z + 1e-3, "sheen r %g at %g deg: eval integrates to %.4f, table %.4f",
                   rs[j], t * 25.0, m.albedo_quad[0], er.f.z);
        }
    }
    close_runner();
}

/* ---- KHR_materials_anisotropy ------------------------------------------------------------- */

/* Strength 0 leaves the glTF base exactly as it is, whatever the rotation: eval, pdf and
 * sample give the same bits as the setting without the extension. */
TEST(brdf, anisotropy_limit)
{
    enum { N = 8192 };
    static const char *bases[] = {"", "metallic=1 roughness=0.3 base-color=0.9,0.6,0.2", "roughness=0",
                                  "transmission=1 roughness=0.4", "transmission=0.5 metallic=0.2 roughness=0",
                                  "clearcoat=0.6 clearcoat-roughness=0.3 roughness=0.5 sheen-color=0.4"};
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    rng_state = 9;
    for (int k = 0; k < (int)(sizeof bases / sizeof *bases); k++) {
        char with[256];
        brdf_setting base, aniso;
        snprintf(with, sizeof with, "%s anisotropy=0 anisotropy-rotation=1.3", bases[k]);
        make_setting(&(config){"gltf", bases[k]}, &base);
        make_setting(&(config){"gltf", with}, &aniso);
        for (int i = 0; i < N / 2; i++) {
            vec3 wo = polar(acos(1 - 2 * rnd()), 2 * PI * rnd()), wi = polar(acos(1 - 2 * rnd()), 2 * PI * rnd());
            vec3 u = rnd_u();
            q[2 * i] = query(&base, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
            q[2 * i + 1] = query(&aniso, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
        }
        brdf_runner_run(&runner, q, r, N);
        int differ = 0;
        for (int i = 0; i < N / 2; i++)
            differ += memcmp(&r[2 * i], &r[2 * i + 1], sizeof *r) != 0;
        CHECKF(differ == 0, "gltf %s: %d of %d queries differ with anisotropy 0", bases[k], differ, N / 2);
    }
    close_runner();
}

/* The anisotropic GGX distribution by quadrature over the hemisphere of half vectors
 * (theta = pi/2 x^2: dense at the pole, where the lobes are narrow): the projected area of
 * the microfacets is the surface's, integral D(h) cos(h) dw = 1, and Smith's masking makes
 * the visible projected area the surface's seen from wo, integral G1(wo) max(0, wo.h) D(h)
 * dw = cos(wo) (Heitz 2014, eqs. 4 and 17). And the lobe is stretched along the rotation:
 * D falls off slower toward (cos r, sin r) than across it. */
TEST(brdf, anisotropy_ndf)
{
    enum { NT = 1600, NP = 720, N = NT * NP };
    static const char *ndf_cases[] = {"roughness=0.2 anisotropy=0.9", "roughness=0.5 anisotropy=0.5 anisotropy-rotation=0.7",
                                  "roughness=0.3 anisotropy=1 anisotropy-rotation=-2",
                                  "roughness=0.1 anisotropy=0.7 anisotropy-rotation=1.5708"};
    static const double wo_deg[] = {0, 45, 75};
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    for (int k = 0; k < (int)(sizeof ndf_cases / sizeof *ndf_cases); k++) {
        brdf_setting s;
        make_setting(&(config){"gltf", ndf_cases[k]}, &s);
        for (int t = 0; t < 3; t++) {
            vec3 wo = polar(rad(wo_deg[t]), 0.4);
            double area = 0, visible = 0;
            for (int i0 = 0; i0 < N; i0 += CHUNK) {
                int n = N - i0 < CHUNK ? N - i0 : CHUNK;
                for (int i = 0; i < n; i++) {
                    int it = (i0 + i) / NP, ip = (i0 + i) % NP;
                    double x = (it + 0.5) / NT, th = PI / 2 * x * x, ph = 2 * PI * (ip + 0.5) / NP;
                    q[i] = query(&s, BRDF_OP_NDF, wo, polar(th, ph), v3(0, 0, 0));
                }
                brdf_runner_run(&runner, q, r, (size_t)n);
                for (int i = 0; i < n; i++) {
                    int it = (i0 + i) / NP;
                    double x = (it + 0.5) / NT, th = PI / 2 * x * x;
                    double dw = sin(th) * (PI * x / NT) * (2 * PI / NP); /* dtheta = pi x dx */
                    vec3 h = q[i].wi;
                    double oh = (double)wo.x * h.x + (double)wo.y * h.y + (double)wo.z * h.z;
                    area += r[i].f.x * cos(th) * dw;
                    visible += r[i].f.y * fmax(0, oh) * r[i].f.x * dw;
                }
            }
            if (t == 0)
                CHECKF(fabs(area - 1) < 2e-3, "gltf %s: integral of D cos = %.5f, not 1", ndf_cases[k], area);
            CHECKF(fabs(visible - wo.z) < 2e-3, "gltf %s wo %g deg: visible projected area %.5f, not cos %.5f",
                   ndf_cases[k], wo_deg[t], visible, wo.z);
        }
        /* 20 degrees off the normal along the direction and across it */
        double rot = s.m.anisotropy_rotation;
        q[0] = query(&s, BRDF_OP_NDF, v3(0, 0, 1), polar(rad(20), rot), v3(0, 0, 0));
        q[1] = query(&s, BRDF_OP_NDF, v3(0, 0, 1), polar(rad(20), rot + PI / 2), v3(0, 0, 0));
        brdf_runner_run(&runner, q, r, 2);
        CHECKF(r[0].f.x > 2 * r[1].f.x, "gltf %s: D along the direction %g, across it %g", ndf_cases[k], r[0].f.x,
               r[1].f.x);
    }
    close_runner();
}

/* ---- KHR_materials_iridescence and _diffuse_transmission -------------------------------------- */

/* The reflectance at cos c of a smooth glTF setting with no diffuse: the weight of its one
 * (mirror) sample, F(wo.z) itself; of smooth glass (glass), the mirror sample's weight F / P
 * times its probability P (u.x = 0 picks the reflection). */
static void mirror_weights(const brdf_setting *s, const double *cs, int n, vec3 *out, bool glass)
{
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    for (int i = 0; i < n; i++)
        q[i] = query(s, BRDF_OP_SAMPLE, polar(acos(cs[i]), 0.5), v3(0, 0, 1), v3(glass ? 0 : 0.5, 0.5, 0.5));
    brdf_runner_run(&runner, q, r, (size_t)n);
    for (int i = 0; i < n; i++) {
        out[i] = r[i].s_weight;
        if (glass) {
            out[i].x *= r[i].s_pdf, out[i].y *= r[i].s_pdf, out[i].z *= r[i].s_pdf;
            if (!(r[i].s_flags & BRDF_FLAG_REFLECTION))
                out[i] = v3(-1, -1, -1); /* no reflection sampled: fails any comparison */
        }
    }
}

/* The CIE 1931 colour-matching functions by Wyman, Sloan and Shirley's multi-lobe Gaussian fit
 * (JCGT 2(2), 2013): independent of the Fourier-space fit the shader integrates with. */
static double cmf_lobe(double l, double mu, double s1, double s2)
{
    double t = (l - mu) / (l < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

/* Linear sRGB of the reflectance at normal incidence of a film of index n2 and thickness d
 * (nm) on a base of F0 f0 (index (1 + sqrt f0) / (1 - sqrt f0)) from the outside (index 1):
 * the Airy sum of the film's reflections, r = (r12 + r23 e^(i delta)) / (1 + r12 r23
 * e^(i delta)), delta = 4 pi n2 d / lambda, integrated over 360-830 nm against the CMFs,
 * each channel divided by that of a flat spectrum (so that a reflectance without a film is
 * its own grey, as the extension's DC term is). */
static void airy_rgb(double n2, double d, double f0, double out[3])
{
    const double m[3][3] = {{3.2404542, -1.5371385, -0.4985314}, {-0.9692660, 1.8760108, 0.0415560},
                            {0.0556434, -0.2040259, 1.0572252}};
    double sf = sqrt(f0), n3 = (1 + sf) / (1 - sf), r12 = (1 - n2) / (1 + n2), r23 = (n2 - n3) / (n2 + n3);
    double xyz[3] = {0}, white[3] = {0};
    for (double l = 360; l <= 830; l += 0.25) {
        double cmf[3] = {1.056 * cmf_lobe(l, 599.8, 37.9, 31.0) + 0.362 * cmf_lobe(l, 442.0, 16.0, 26.7) -
                             0.065 * cmf_lobe(l, 501.1, 20.4, 26.2),
                         0.821 * cmf_lobe(l, 568.8, 46.9, 40.5) + 0.286 * cmf_lobe(l, 530.9, 16.3, 31.1),
                         1.217 * cmf_lobe(l, 437.0, 11.8, 36.0) + 0.681 * cmf_lobe(l, 459.0, 26.0, 13.8)};
        double complex e = cexp(I * 4 * PI * n2 * d / l), r = (r12 + r23 * e) / (1 + r12 * r23 * e);
        double refl = creal(r * conj(r));
        for (int k = 0; k < 3; k++) {
            xyz[k] += refl * cmf[k];
            white[k] += cmf[k];
        }
    }
    for (int c = 0; c < 3; c++) {
        double v = 0, w = 0;
        for (int k = 0; k < 3; k++) {
            v += m[c][k] * xyz[k];
            w += m[c][k] * white[k];
        }
        out[c] = v / w;
    }
}

/* The film at normal incidence against the Airy formula integrated over the spectrum, for
 * thicknesses 0-1500 nm on a dielectric (F0 0.04), a metal-like base (F0 0.9) and glass
 * (F0 0.04, the film on its reflection, which the transmission gets 1 - F of). The
 * extension's RGB evaluation is an approximation (Schlick's interfaces, two orders of
 * interference, and the interference terms' colour not white-balanced as the DC term is):
 * measured here within 0.007 (dielectric) and 0.013 (F0 0.9) of the reference; a thickness
 * 10% off is 0.04 and 0.07 away. */
TEST(brdf, iridescence_airy)
{
    static const struct { const char *base; double f0, n2, tol; bool glass; } airy_cases[] = {
        {"base-color=0 ior=1.5", 0.04, 1.3, 0.01, false},
        {"metallic=1 base-color=0.9", 0.9, 1.3, 0.02, false},
        {"transmission=1 ior=1.5", 0.04, 1.3, 0.01, true}, /* the film on glass (brdf_glass_fresnel) */
    };
    enum { ND = 76 };
    if (!open_runner())
        return;
    for (int k = 0; k < 3; k++) {
        double worst = 0, at = 0, one = 1;
        int bad = 0;
        for (int j = 0; j < ND; j++) {
            char params[200];
            double d = 20.0 * j, ref[3];
            brdf_setting s;
            vec3 w;
            snprintf(params, sizeof params, "%s roughness=0 iridescence=1 iridescence-ior=%g iridescence-thickness=%g",
                     airy_cases[k].base, airy_cases[k].n2, d);
            make_setting(&(config){"gltf", params}, &s);
            mirror_weights(&s, &one, 1, &w, airy_cases[k].glass);
            airy_rgb(airy_cases[k].n2, d, airy_cases[k].f0, ref);
            for (int c = 0; c < 3; c++) {
                double e = fabs((&w.x)[c] - ref[c]);
                if (e > worst)
                    worst = e, at = d;
                bad += e > airy_cases[k].tol;
            }
        }
        printf("    F0 %g, film %g: worst |F_film - Airy| %.4f (at %g nm)\n", airy_cases[k].f0, airy_cases[k].n2, worst, at);
        CHECKF(bad == 0, "F0 %g film ior %g: %d channels off the Airy reference by more than %g (worst %.4f at %g nm)",
               airy_cases[k].f0, airy_cases[k].n2, bad, airy_cases[k].tol, worst, at);
    }
    close_runner();
}

/* The film's limits: thickness 0 and a film of the outside's index (1) are no film, and a
 * factor of 1 then gives the base's own f and pdf (the lobe's Schlick F and the diffuse
 * coupled to it; dielectric, metal, a mix with a specular factor; rough and smooth) and the
 * glass's exact F (rough and smooth glass), over random directions on both sides. */
TEST(brdf, iridescence_limits)
{
    static const char *bases[] = {"base-color=0.8 ior=1.5 roughness=0.4", "metallic=1 base-color=0.9,0.6,0.2 roughness=0.3",
                                  "metallic=0.4 base-color=0.5,0.8,0.3 ior=1.7 specular=0.8 roughness=0.5",
                                  "base-color=0.8 roughness=0", "transmission=1 roughness=0.3 ior=1.5",
                                  "transmission=1 roughness=0 ior=1.4 base-color=0.9,0.8,0.6"};
    static const char *films[] = {"iridescence-thickness=0 iridescence-ior=1.8", "iridescence-thickness=500 iridescence-ior=1"};
    enum { N = 4096 };
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    rng_state = 10;
    for (int k = 0; k < 6; k++)
        for (int f = 0; f < 2; f++) {
            char params[256];
            brdf_setting plain, film;
            int bad = 0, nonzero = 0;
            make_setting(&(config){"gltf", bases[k]}, &plain);
            snprintf(params, sizeof params, "%s iridescence=1 %s", bases[k], films[f]);
            make_setting(&(config){"gltf", params}, &film);
            for (int i = 0; i < N / 2; i++) {
                vec3 wo = polar(acos(rnd()), 2 * PI * rnd()), wi = polar(acos(rnd()), 2 * PI * rnd()), u = rnd_u();
                q[2 * i] = query(&plain, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
                q[2 * i + 1] = query(&film, BRDF_OP_EVAL | BRDF_OP_SAMPLE, wo, wi, u);
            }
            brdf_runner_run(&runner, q, r, N);
            for (int i = 0; i < N / 2; i++) {
                const float *x = &r[2 * i].f.x, *y = &r[2 * i + 1].f.x, *xs = &r[2 * i].s_weight.x,
                            *ys = &r[2 * i + 1].s_weight.x;
                for (int c = 0; c < 3; c++) {
                    bad += fabs(x[c] - y[c]) > 1e-4 * fabs(x[c]) + 1e-7;
                    bad += fabs(xs[c] - ys[c]) > 1e-4 * fabs(xs[c]) + 1e-7;
                    nonzero += x[c] > 0 || xs[c] > 0;
                }
                bad += fabs(r[2 * i].pdf - r[2 * i + 1].pdf) > 1e-4 * r[2 * i].pdf + 1e-7;
            }
            CHECKF(bad == 0, "%s with %s: %d values differ from the base's", bases[k], films[f], bad);
            CHECKF(nonzero > N / 2, "%s: only %d non-zero values", bases[k], nonzero);
        }
    close_runner();
}

/* The film on smooth glass (white, index 1.5): reflection and transmission share the light,
 * R + T = 1 per channel, each the weight of its sample (u.x = 0 picks the reflection, u.x near
 * 1 the transmission) times its probability, from outside and from inside below the critical
 * angle; and the reflectance seen from inside at theta_i is the one from outside at the angle
 * Snell's law pairs it with (both at the outside's cosine), for three films. */
TEST(brdf, iridescence_glass)
{
    static const char *films[] = {"iridescence-thickness=250", "iridescence-thickness=600 iridescence-ior=1.8",
                                  "iridescence=0.5 iridescence-thickness=400"};
    static const double out_deg[] = {0, 30, 55, 75, 85};
    enum { NA = 5 };
    const double n = 1.5;
    if (!open_runner())
        return;
    BrdfQuery *q = qbuf;
    BrdfResult *r = rbuf;
    for (int f = 0; f < 3; f++) {
        char params[200];
        brdf_setting s;
        snprintf(params, sizeof params, "transmission=1 roughness=0 base-color=1 ior=%g iridescence=1 %s", n, films[f]);
        make_setting(&(config){"gltf", params}, &s);
        /* side 0: wo outside at theta_o; side 1: wo inside at theta_i, sin theta_o = n sin theta_i */
        for (int side = 0; side < 2; side++)
            for (int a = 0; a < NA; a++) {
                double to = out_deg[a] * PI / 180, ti = asin(sin(to) / n);
                vec3 wo = side ? polar(PI - ti, 0.3) : polar(to, 0.3);
                for (int k = 0; k < 2; k++)
                    q[(side * NA + a) * 2 + k] = query(&s, BRDF_OP_SAMPLE, wo, v3(0, 0, 1), v3(k ? 0.99999 : 0, 0.5, 0.5));
            }
        brdf_runner_run(&runner, q, r, 4 * NA);
        double worst_sum = 0, worst_side = 0, spread = 0;
        int wrong = 0;
        for (int a = 0; a < NA; a++) {
            double refl[2][3];
            for (int side = 0; side < 2; side++) {
                const BrdfResult *x = &r[(side * NA + a) * 2], *y = x + 1;
                wrong += !(x->s_flags & BRDF_FLAG_REFLECTION) || !(y->s_flags & BRDF_FLAG_TRANSMISSION);
                for (int c = 0; c < 3; c++) {
                    refl[side][c] = (&x->s_weight.x)[c] * x->s_pdf;
                    worst_sum = fmax(worst_sum, fabs(refl[side][c] + (&y->s_weight.x)[c] * y->s_pdf - 1));
                }
            }
            for (int c = 0; c < 3; c++)
                worst_side = fmax(worst_side, fabs(refl[0][c] - refl[1][c]));
            spread = fmax(spread, fmax(fabs(refl[0][0] - refl[0][1]), fabs(refl[0][1] - refl[0][2])));
        }
        printf("    %s: worst |R + T - 1| %.2g, worst |R_out - R_in| %.2g, colour spread of R up to %.3f\n", films[f],
               worst_sum, worst_side, spread);
        CHECKF(wrong == 0, "%s: %d samples not of the part u.x picks", films[f], wrong);
        CHECKF(worst_sum < 1e-5, "%s: R + T off 1 by %g", films[f], worst_sum);
        CHECKF(worst_side < 1e-4, "%s: the reflectances from the two sides differ by %g", films[f], worst_side);
        CHECKF(spread > 0.005, "%s: the film colours nothing (channels within %g)", films[f], spread);
    }
    close_runner();
}

/* Diffuse transmission: a white base with no specular lobe and a transmission of factor k and
 * colour c reflects (1 - k) and transmits k c, by quadrature of eval over each hemisphere, from
 * either side (the reflection only from the front: the lobe is Lambert's there), at several
 * angles; and the lobe is cosine-distributed: f of the transmission is k c / pi everywhere. */
TEST(brdf, diffuse_transmission)
{
    static const double ks[] = {0.25, 0.7, 1}, col[3] = {0.9, 0.5, 0.2}, theta[] = {0, 40, 80, 120, 170};
    if (!open_runner())
        return;
    rng_state = 9;
    for (int a = 0; a < 3; a++) {
        char params[200];
        brdf_setting s;
        snprintf(params, sizeof params, "base-color=1 specular=0 diffuse-transmission=%g "
                 "diffuse-transmission-color=%g,%g,%g", ks[a], col[0], col[1], col[2]);
        make_setting(&(config){"gltf", params}, &s);
        for (int t = 0; t < 5; t++) {
            vec3 wo = polar(rad(theta[t]), 0.8);
            double refl[3] = {0}, trans[3] = {0};
            BrdfQuery *q = qbuf;
            BrdfResult *r = rbuf;
            for (int k0 = 0; k0 < NGRID; k0 += CHUNK) {
                int n = NGRID - k0 < CHUNK ? NGRID - k0 : CHUNK, badf = 0;
                for (int i = 0; i < n; i++)
                    q[i] = query(&s, BRDF_OP_EVAL, wo, grid_dir[k0 + i], v3(0, 0, 0));
                brdf_runner_run(&runner, q, r, (size_t)n);
                for (int i = 0; i < n; i++) {
                    bool same = q[i].wi.z * wo.z > 0;
                    double w = grid_weight[k0 + i] * fabs(q[i].wi.z);
                    for (int c = 0; c < 3; c++) {
                        double f = (&r[i].f.x)[c];
                        (same ? refl : trans)[c] += f * w;
                        if (!same && fabs(f - ks[a] * col[c] / PI) > 1e-6)
                            badf++;
                    }
                }
                CHECKF(badf == 0, "k %g wo %g: %d transmitted f != k c / pi", ks[a], theta[t], badf);
            }
            for (int c = 0; c < 3; c++) {
                double want_r = wo.z > 0 ? 1 - ks[a] : 0, want_t = ks[a] * col[c];
                CHECKF(fabs(refl[c] - want_r) < 1e-3, "k %g wo %g ch %d: reflected %.5f != %.5f", ks[a], theta[t], c,
                       refl[c], want_r);
                CHECKF(fabs(trans[c] - want_t) < 1e-3, "k %g wo %g ch %d: transmitted %.5f != %.5f", ks[a], theta[t],
                       c, trans[c], want_t);
            }
        }
    }
    close_runner();
}
