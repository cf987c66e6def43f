/* test_shading.c: the three shading algorithms of docs/shading.md on the Vulkan device
 * (glsl/kernels/local.comp, glsl/kernels/vertex.comp) against the Phong reflection model written out again here in
 * C: Gouraud's vertex colours and their barycentric interpolation, flat shading's one colour
 * per triangle, per-pixel Phong shading converging to the analytic sphere, and the highlight
 * inside a triangle that Gouraud shading misses. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "gpu.h"
#include "meshgen.h"
#include "render.h"
#include "scene_mesh.h"
#include "test.h"
#include "util.h"

typedef struct shade_params {
    float kd[3], ks[3], ka[3], ke[3], shininess, ambient[3];
    GnLight light;
} shade_params;

/* A scene of one mesh with the given Phong material, global ambient light and one light. */
static void make_scene(scene *sc, const meshgen_mesh *m, const shade_params *p)
{
    GnMaterial *mat;
    scene_from_mesh(sc, "test", m->num_vertices, m->positions, m->normals, m->num_triangles,
                    m->indices);
    mat = &sc->materials[0];
    mat->phong_diffuse = (vec3){p->kd[0], p->kd[1], p->kd[2]};
    mat->phong_specular = (vec3){p->ks[0], p->ks[1], p->ks[2]};
    mat->phong_ambient = (vec3){p->ka[0], p->ka[1], p->ka[2]};
    mat->phong_emission = (vec3){p->ke[0], p->ke[1], p->ke[2]};
    mat->phong_shininess = p->shininess;
    memcpy(sc->ambient, p->ambient, sizeof sc->ambient);
    sc->num_lights = 1;
    sc->lights = util_malloc(sizeof *sc->lights);
    sc->lights[0] = p->light;
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void normalize3(double v[3])
{
    double l = sqrt(dot3(v, v));
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

/* The Phong reflection model, from its formula (docs/shading.md): emission + ambient light * ka +
 * E (kd (n.l) + ks (r.v)^s), r = 2 (n.l) n - l; a light behind the surface adds nothing.
 * Point lights fall off as 1/d^2. n, v unit. */
static void phong_ref(const shade_params *p, const double pos[3], const double n[3],
                      const double v[3], double out[3])
{
    const GnLight *l = &p->light;
    double wi[3], E = 1, ndl, r[3], rv, spec;
    if (l->type == GN_LIGHT_DIRECTIONAL) {
        wi[0] = -l->direction.x, wi[1] = -l->direction.y, wi[2] = -l->direction.z;
    } else {
        wi[0] = l->position.x - pos[0], wi[1] = l->position.y - pos[1], wi[2] = l->position.z - pos[2];
        E = 1 / dot3(wi, wi);
    }
    normalize3(wi);
    ndl = dot3(n, wi);
    for (int k = 0; k < 3; k++)
        r[k] = 2 * ndl * n[k] - wi[k];
    rv = dot3(r, v);
    spec = pow(rv > 0 ? rv : 0, p->shininess);
    for (int k = 0; k < 3; k++) {
        const float *c = &l->color.x;
        out[k] = p->ke[k] + p->ambient[k] * p->ka[k];
        if (ndl > 0)
            out[k] += E * c[k] * (p->kd[k] * ndl + p->ks[k] * spec);
    }
}

typedef struct render_out {
    image img;
    GnCamera cam;
    float *vcolor; /* 8 floats per vertex (front rgb w, back rgb w); NULL unless asked for */
} render_out;

/* The framing camera's distance and planes, but looking straight down -Z: the tests'
 * geometry (a highlight below a light, a triangle facing the camera) is laid out for it. */
static void straight_down_z(const scene *sc, float aspect, scene_camera *c)
{
    scene_default_camera(sc, aspect, c);
    float centre[3], dist = 0;
    for (int k = 0; k < 3; k++) {
        centre[k] = 0.5f * (sc->bounds_min[k] + sc->bounds_max[k]);
        dist += (c->position[k] - centre[k]) * (c->position[k] - centre[k]);
    }
    dist = sqrtf(dist);
    memset(c->right, 0, sizeof c->right);
    memset(c->up, 0, sizeof c->up);
    memset(c->forward, 0, sizeof c->forward);
    c->right[0] = c->up[1] = 1;
    c->forward[2] = -1;
    c->position[0] = centre[0];
    c->position[1] = centre[1];
    c->position[2] = centre[2] + dist;
}

/* Renders sc in `mode`, one sample per pixel (sample 0 goes through pixel centres). */
static bool render_scene(const scene *sc, uint32_t mode, int w, int h, bool want_vcolor,
                         render_out *out)
{
    const char *env = getenv("GONIO_VALIDATE");
    gpu_desc d = {.device_index = -1, .validate = env && !strcmp(env, "1")};
    scene_camera view;
    straight_down_z(sc, (float)w / (float)h, &view);
    render_settings s = {.mode = mode, .width = w, .height = h, .spp = 1, .camera = -1,
                         .view = &view};
    render_stats st;
    renderer r;
    gpu g;
    bool ok;
    memset(out, 0, sizeof *out);
    if (!gpu_create(&g, &d)) {
        CHECKF(false, "no Vulkan device");
        return false;
    }
    renderer_create(&r, &g, sc);
    ok = renderer_render(&r, &s, &out->img, &st) && renderer_camera(&r, &s, &out->cam);
    CHECKF(ok, "render in mode %s failed", render_mode_name(mode));
    if (ok && want_vcolor) {
        out->vcolor = util_malloc(32 * (size_t)sc->num_vertices);
        gpu_buffer_download(&g, &r.gouraud.vcolor, out->vcolor, 32 * (VkDeviceSize)sc->num_vertices, 0);
    }
    renderer_destroy(&r);
    gpu_destroy(&g);
    return ok;
}

static void render_out_destroy(render_out *o)
{
    image_destroy(&o->img);
    free(o->vcolor);
}

/* The camera ray through the centre of pixel (x, y), as GnCamera defines it. */
static void pixel_ray(const GnCamera *c, int w, int h, int x, int y, double d[3])
{
    double nx = 2.0 * (x + 0.5) / w - 1, ny = 1 - 2.0 * (y + 0.5) / h;
    const float *f = &c->forward.x, *r = &c->right.x, *u = &c->up.x;
    for (int k = 0; k < 3; k++)
        d[k] = f[k] + nx * c->tan_half_fovy * c->aspect * r[k] + ny * c->tan_half_fovy * u[k];
    normalize3(d);
}

static void to_camera(const GnCamera *c, const double p[3], double v[3])
{
    v[0] = c->position.x - p[0], v[1] = c->position.y - p[1], v[2] = c->position.z - p[2];
    normalize3(v);
}

/* One large triangle in z = 0 facing +z, with three different vertex normals. */
static meshgen_mesh big_triangle(const float normals[9])
{
    static const float pos[9] = {-1, -0.8f, 0, 1, -0.8f, 0, 0, 1.2f, 0};
    meshgen_mesh m = {.num_vertices = 3, .num_triangles = 1};
    m.positions = util_malloc(sizeof pos);
    m.normals = util_malloc(9 * sizeof(float));
    m.indices = util_malloc(3 * sizeof(uint32_t));
    memcpy(m.positions, pos, sizeof pos);
    memcpy(m.normals, normals, 9 * sizeof(float));
    for (uint32_t i = 0; i < 3; i++)
        m.indices[i] = i;
    return m;
}

/* Barycentrics (of v0, v1, v2) of the camera ray's hit with the plane z = 0 in big_triangle. */
static bool plane_barycentrics(const GnCamera *c, const double d[3], const float *pos, double b[3],
                               double p[3])
{
    double t = -c->position.z / d[2], x0 = pos[0], y0 = pos[1];
    double e1x = pos[3] - x0, e1y = pos[4] - y0, e2x = pos[6] - x0, e2y = pos[7] - y0, det;
    p[0] = c->position.x + t * d[0], p[1] = c->position.y + t * d[1], p[2] = 0;
    det = e1x * e2y - e1y * e2x;
    b[1] = ((p[0] - x0) * e2y - (p[1] - y0) * e2x) / det;
    b[2] = (e1x * (p[1] - y0) - e1y * (p[0] - x0)) / det;
    b[0] = 1 - b[1] - b[2];
    return t > 0;
}

static void unit_normals(float n[9])
{
    for (int i = 0; i < 3; i++) {
        float l = sqrtf(n[3 * i] * n[3 * i] + n[3 * i + 1] * n[3 * i + 1] + n[3 * i + 2] * n[3 * i + 2]);
        for (int k = 0; k < 3; k++)
            n[3 * i + k] /= l;
    }
}

/* Gouraud: the vertex pass lights each vertex with its own normal and the view direction
 * from that vertex (and the opposite side with the flipped normal), and every pixel inside
 * the triangle is the barycentric interpolation of those colours. */
TEST(shading, gouraud_triangle)
{
    float normals[9] = {0.3f, 0, 1, -0.2f, 0.3f, 1, 0, -0.4f, 1};
    shade_params p = {.kd = {0.6f, 0.3f, 0.2f}, .ks = {0.5f, 0.4f, 0.3f}, .ka = {0.1f, 0.2f, 0.3f},
                      .ke = {0.01f, 0.02f, 0.03f}, .shininess = 8, .ambient = {0.5f, 0.5f, 0.5f},
                      .light = {.type = GN_LIGHT_DIRECTIONAL, .color = {1, 0.9f, 0.8f}}};
    double dl[3] = {-0.3, -0.5, -1}, vc[3][3], worst = 0;
    meshgen_mesh m;
    scene sc;
    render_out o;
    int inside = 0;
    unit_normals(normals);
    normalize3(dl);
    p.light.direction = (vec3){(float)dl[0], (float)dl[1], (float)dl[2]};
    m = big_triangle(normals);
    make_scene(&sc, &m, &p);
    if (render_scene(&sc, GN_MODE_GOURAUD, 64, 64, true, &o)) {
        for (int i = 0; i < 3; i++) {
            double pos[3] = {m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]};
            double n[3] = {normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]}, back[3], v[3];
            to_camera(&o.cam, pos, v);
            phong_ref(&p, pos, n, v, vc[i]);
            for (int k = 0; k < 3; k++)
                n[k] = -n[k];
            phong_ref(&p, pos, n, v, back);
            for (int k = 0; k < 3; k++) {
                CHECKF(fabs(o.vcolor[8 * i + k] - vc[i][k]) < 1e-5 * (1 + vc[i][k]),
                       "vertex %d channel %d: front %g, expected %g", i, k, o.vcolor[8 * i + k], vc[i][k]);
                CHECKF(fabs(o.vcolor[8 * i + 4 + k] - back[k]) < 1e-5,
                       "vertex %d channel %d: back %g, expected %g", i, k, o.vcolor[8 * i + 4 + k], back[k]);
            }
        }
        for (int y = 0; y < 64; y++)
            for (int x = 0; x < 64; x++) {
                double d[3], b[3], pt[3];
                size_t px = (size_t)y * 64 + x;
                pixel_ray(&o.cam, 64, 64, x, y, d);
                if (!plane_barycentrics(&o.cam, d, m.positions, b, pt) || b[0] < 1e-3 ||
                    b[1] < 1e-3 || b[2] < 1e-3)
                    continue;
                inside++;
                for (int k = 0; k < 3; k++) {
                    double want = b[0] * vc[0][k] + b[1] * vc[1][k] + b[2] * vc[2][k];
                    worst = fmax(worst, fabs(o.img.planes[k][px] - want));
                }
            }
        CHECKF(inside > 500, "only %d pixels inside the triangle", inside);
        CHECKF(worst < 1e-4, "Gouraud pixels differ from the barycentric interpolation by %g", worst);
        /* The vertex colours differ, so the interpolation is really tested. */
        CHECK(fabs(vc[0][0] - vc[1][0]) > 0.05 && fabs(vc[1][0] - vc[2][0]) > 0.05);
    }
    render_out_destroy(&o);
    scene_destroy(&sc);
    meshgen_destroy(&m);
}

/* Flat: every pixel of a triangle has the colour of the Phong model at its centroid with
 * the face normal, seen from the centroid; neighbouring triangles differ. */
TEST(shading, flat_constant)
{
    const float centre[3] = {0, 0, 0};
    shade_params p = {.kd = {0.7f, 0.5f, 0.3f}, .ks = {0.4f, 0.4f, 0.4f}, .shininess = 16,
                      .light = {.type = GN_LIGHT_DIRECTIONAL, .color = {1, 1, 1}}};
    double dl[3] = {-0.5, -0.6, -0.8}, worst = 0;
    meshgen_mesh m = meshgen_uv_sphere(centre, 1, 12, 8);
    scene sc;
    render_out o;
    int checked = 0, distinct = 0;
    float first = -1;
    normalize3(dl);
    p.light.direction = (vec3){(float)dl[0], (float)dl[1], (float)dl[2]};
    make_scene(&sc, &m, &p);
    if (render_scene(&sc, GN_MODE_FLAT, 64, 64, false, &o)) {
        for (int y = 0; y < 64; y++)
            for (int x = 0; x < 64; x++) {
                double d[3], c[3] = {0, 0, 0}, e1[3], e2[3], n[3], v[3], want[3];
                float org[3] = {o.cam.position.x, o.cam.position.y, o.cam.position.z}, df[3];
                size_t px = (size_t)y * 64 + x;
                bvh_hit h;
                const float *q[3];
                pixel_ray(&o.cam, 64, 64, x, y, d);
                for (int k = 0; k < 3; k++)
                    df[k] = (float)d[k];
                h = bvh_brute_force(m.positions, 3, m.indices, m.num_triangles, org, df, 0, 1e30f);
                /* Away from edges, where the GPU and C could pick different triangles. */
                if (h.tri == GN_INVALID || h.u < 0.02f || h.v < 0.02f || 1 - h.u - h.v < 0.02f)
                    continue;
                for (int i = 0; i < 3; i++)
                    q[i] = &m.positions[3 * m.indices[3 * h.tri + i]];
                for (int k = 0; k < 3; k++) {
                    c[k] = (q[0][k] + q[1][k] + q[2][k]) / 3.0;
                    e1[k] = q[1][k] - q[0][k];
                    e2[k] = q[2][k] - q[0][k];
                }
                n[0] = e1[1] * e2[2] - e1[2] * e2[1];
                n[1] = e1[2] * e2[0] - e1[0] * e2[2];
                n[2] = e1[0] * e2[1] - e1[1] * e2[0];
                normalize3(n);
                if (dot3(n, d) > 0)
                    for (int k = 0; k < 3; k++)
                        n[k] = -n[k];
                to_camera(&o.cam, c, v);
                phong_ref(&p, c, n, v, want);
                for (int k = 0; k < 3; k++)
                    worst = fmax(worst, fabs(o.img.planes[k][px] - want[k]));
                checked++;
                if (first < 0)
                    first = o.img.planes[0][px];
                else if (fabsf(o.img.planes[0][px] - first) > 0.01f)
                    distinct++;
            }
        CHECKF(checked > 600, "only %d pixels checked", checked);
        CHECKF(distinct > 100, "flat shading gave nearly one colour (%d pixels differ)", distinct);
        CHECKF(worst < 1e-4, "flat pixels differ from the centroid's Phong colour by %g", worst);
    }
    render_out_destroy(&o);
    scene_destroy(&sc);
    meshgen_destroy(&m);
}

/* Phong shading of sphere meshes approaches the analytic sphere's shading (exact normal at
 * the exact hit) as the tessellation grows: the error falls at every step and ends small. */
TEST(shading, phong_sphere)
{
    const float centre[3] = {0, 0, 0};
    shade_params p = {.kd = {0.6f, 0.6f, 0.6f}, .ks = {0.5f, 0.5f, 0.5f}, .shininess = 20,
                      .light = {.type = GN_LIGHT_DIRECTIONAL, .color = {1, 1, 1}}};
    double dl[3] = {-0.4, -0.5, -0.8}, last = 1e30;
    const uint32_t slices[] = {8, 16, 32, 128};
    normalize3(dl);
    p.light.direction = (vec3){(float)dl[0], (float)dl[1], (float)dl[2]};
    for (size_t i = 0; i < sizeof slices / sizeof *slices; i++) {
        meshgen_mesh m = meshgen_uv_sphere(centre, 1, slices[i], slices[i] / 2);
        scene sc;
        render_out o;
        double sum = 0, rmse;
        int count = 0;
        make_scene(&sc, &m, &p);
        if (render_scene(&sc, GN_MODE_PHONG, 64, 64, false, &o)) {
            for (int y = 0; y < 64; y++)
                for (int x = 0; x < 64; x++) {
                    double d[3], oc[3] = {o.cam.position.x, o.cam.position.y, o.cam.position.z};
                    double b, disc, t, pt[3], v[3], want[3];
                    size_t px = (size_t)y * 64 + x;
                    pixel_ray(&o.cam, 64, 64, x, y, d);
                    b = dot3(oc, d);
                    disc = b * b - (dot3(oc, oc) - 1);
                    /* Inside the silhouette of every tessellation (cos > 0.5 at the hit). */
                    if (disc < 0 || sqrt(disc) < 0.5 || o.img.planes[3][px] < 1)
                        continue;
                    t = -b - sqrt(disc);
                    for (int k = 0; k < 3; k++) {
                        pt[k] = oc[k] + t * d[k];
                        v[k] = -d[k];
                    }
                    phong_ref(&p, pt, pt, v, want); /* unit sphere: the normal is the point */
                    for (int k = 0; k < 3; k++)
                        sum += (o.img.planes[k][px] - want[k]) * (o.img.planes[k][px] - want[k]);
                    count += 3;
                }
            rmse = count ? sqrt(sum / count) : 1e30;
            printf("    sphere %u x %u: phong vs analytic rmse %.5f over %d pixels\n", slices[i],
                   slices[i] / 2, rmse, count / 3);
            CHECKF(count > 3 * 500, "only %d pixels compared", count / 3);
            CHECKF(rmse < last, "rmse %g at %u slices is not below %g", rmse, slices[i], last);
            last = rmse;
        }
        render_out_destroy(&o);
        scene_destroy(&sc);
        meshgen_destroy(&m);
    }
    CHECKF(last < 5e-3, "finest sphere still %g from the analytic shading", last);
}

/* The classic failure of Gouraud shading: a point light above the middle of a large flat
 * triangle puts a sharp highlight inside it that reaches none of its vertices. Per-pixel
 * Phong shading shows it; Gouraud shading, which only knows the vertex colours, cannot. */
TEST(shading, highlight_missed)
{
    const float up[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    shade_params p = {.kd = {0.1f, 0.1f, 0.1f}, .ks = {1, 1, 1}, .shininess = 200,
                      .light = {.type = GN_LIGHT_POINT, .position = {0, 0.2f, 0.5f}, .color = {0.25f, 0.25f, 0.25f}}};
    meshgen_mesh m = big_triangle(up);
    scene sc;
    render_out ph = {0}, go = {0};
    make_scene(&sc, &m, &p);
    /* An odd size puts a pixel centre on the mirror point below the light. */
    if (render_scene(&sc, GN_MODE_PHONG, 65, 65, false, &ph) &&
        render_scene(&sc, GN_MODE_GOURAUD, 65, 65, false, &go)) {
        double vmax = 0, gmax = 0, pmax = 0, peak = 0.25 / (0.5 * 0.5); /* E = I / h^2 */
        for (int i = 0; i < 3; i++) {
            double pos[3] = {m.positions[3 * i], m.positions[3 * i + 1], 0}, n[3] = {0, 0, 1}, v[3], c[3];
            to_camera(&go.cam, pos, v);
            phong_ref(&p, pos, n, v, c);
            vmax = fmax(vmax, c[0]);
        }
        for (size_t px = 0; px < 65 * 65; px++) {
            gmax = fmax(gmax, go.img.planes[0][px]);
            pmax = fmax(pmax, ph.img.planes[0][px]);
        }
        printf("    highlight: phong max %.3f, gouraud max %.3f, brightest vertex %.3f\n", pmax,
               gmax, vmax);
        CHECKF(pmax > 0.8 * peak, "per-pixel Phong shows no highlight (max %g, peak %g)", pmax, peak);
        CHECKF(gmax <= vmax + 1e-4, "Gouraud is brighter (%g) than its brightest vertex (%g)", gmax, vmax);
        CHECKF(gmax < 0.1 * pmax, "Gouraud shows the highlight (%g vs %g)", gmax, pmax);
    }
    render_out_destroy(&ph);
    render_out_destroy(&go);
    scene_destroy(&sc);
    meshgen_destroy(&m);
}
