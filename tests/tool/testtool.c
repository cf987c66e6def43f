/* testtool.c: scenes with analytic answers, and those answers as EXR images, for the shell
 * regression tests. The references are computed here from the geometry's equations (ray
 * and plane, ray and sphere) with a camera model written out independently of the
 * renderer's, so a render that matches them is right for reasons of its own.
 *
 *   testtool scene NAME OUT.gltf       NAME: plane, inside-sphere
 *   testtool ref NAME AOV W H OUT.exr [SHIFT]  AOV: depth, normal; SHIFT: pixels, in x
 *                                      (a deliberately wrong reference, to show a test fails)
 *   testtool stats IMAGE.exr           coverage, mean luminance, the box of red pixels
 *   testtool same WHOLE.exr PART.exr   every value of PART's channels (but sum.*) equals,
 *                                      bit for bit, WHOLE's at the same display-window pixel
 *   testtool ktx2 MODE IN.png OUT.ktx2 [rg]   a KTX2 image by Basis Universal's encoder
 *   testtool texels IMAGE REF.png CHANNELS MAX_ERR MAX_RMSE   a WebP or KTX2 image as gonio
 *                                      decodes it, against the PNG it was made from
 *   testtool at IN.exr CHANNEL X Y [X Y...]  the channel's value at each pixel, a line each
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_write.h"
#include "image.h"
#include "image_decode.h"
#include "meshgen.h"
#include "util.h"

/* The camera of both scenes: at `eye`, looking along -Z of a rotation about Y by `yaw`
 * then about X by `pitch`; yfov 50 degrees; square images. */
typedef struct view {
    double eye[3], yaw, pitch, yfov;
} view;

static const view plane_view = {{0.2, 0.5, 3.0}, 0.3, -0.25, 50.0 * M_PI / 180.0};
static const view sphere_view = {{0.3, -0.2, 0.25}, 1.1, 0.35, 60.0 * M_PI / 180.0};

/* The plane: through (0, 0, -1) with normal n (unit), a 40 x 40 quad. */
static const double plane_n[3] = {0.26726124191, 0.53452248382, 0.80178372573}; /* (1,2,3)/sqrt14 */

static void basis(const view *v, double right[3], double up[3], double fwd[3])
{
    double cy = cos(v->yaw), sy = sin(v->yaw), cp = cos(v->pitch), sp = sin(v->pitch);
    /* R = Ry(yaw) Rx(pitch): columns are the camera's x, y, z axes in the world */
    right[0] = cy, right[1] = 0, right[2] = -sy;
    up[0] = sy * sp, up[1] = cp, up[2] = cy * sp;
    fwd[0] = -(sy * cp), fwd[1] = sp, fwd[2] = -(cy * cp); /* -z column */
}

static void quat(const view *v, float q[4])
{
    /* q = qy(yaw) * qx(pitch) */
    double hy = 0.5 * v->yaw, hp = 0.5 * v->pitch;
    double ay[4] = {0, sin(hy), 0, cos(hy)}, ax[4] = {sin(hp), 0, 0, cos(hp)};
    q[0] = (float)(ay[3] * ax[0] + ay[0] * ax[3] + ay[1] * ax[2] - ay[2] * ax[1]);
    q[1] = (float)(ay[3] * ax[1] - ay[0] * ax[2] + ay[1] * ax[3] + ay[2] * ax[0]);
    q[2] = (float)(ay[3] * ax[2] + ay[0] * ax[1] - ay[1] * ax[0] + ay[2] * ax[3]);
    q[3] = (float)(ay[3] * ax[3] - ay[0] * ax[0] - ay[1] * ax[1] - ay[2] * ax[2]);
}

static int write_scene(const char *name, const char *out)
{
    gltf_write_camera cam = {.name = "camera", .aspect = 1.0f, .znear = 0.001f};
    /* double-sided: the sphere is seen from inside, the back of its outward winding (a
     * single-sided one would be culled for camera rays, as glTF's doubleSided false says) */
    gltf_write_material mat = {.name = "grey", .base_color = {0.5f, 0.5f, 0.5f, 1}, .roughness = 1,
                               .double_sided = true};
    gltf_write_node nodes[2] = {{.name = "mesh", .kind = GLTF_WRITE_NODE_MESH},
                                {.name = "camera", .kind = GLTF_WRITE_NODE_CAMERA}};
    gltf_write_mesh mesh = {.name = name};
    gltf_write_desc d = {&mesh, 1, &mat, 1, &cam, 1, NULL, 0, nodes, 2};
    const view *v;
    float pos[12], nrm[12];
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    meshgen_mesh m = {0};
    bool ok;

    if (!strcmp(name, "plane")) {
        /* a 40 x 40 square in the plane, corners c +- 20 t1 +- 20 t2 */
        double t1[3] = {0.89442719, -0.44721360, 0}, t2[3], c[3] = {0, 0, -1};
        t2[0] = plane_n[1] * t1[2] - plane_n[2] * t1[1];
        t2[1] = plane_n[2] * t1[0] - plane_n[0] * t1[2];
        t2[2] = plane_n[0] * t1[1] - plane_n[1] * t1[0];
        for (int i = 0; i < 4; i++) {
            double a = (i == 1 || i == 2) ? 20 : -20, b = (i >= 2) ? 20 : -20;
            for (int k = 0; k < 3; k++) {
                pos[3 * i + k] = (float)(c[k] + a * t1[k] + b * t2[k]);
                nrm[3 * i + k] = (float)plane_n[k];
            }
        }
        mesh.num_vertices = 4;
        mesh.positions = pos;
        mesh.normals = nrm;
        mesh.num_indices = 6;
        mesh.indices = idx;
        v = &plane_view;
    } else if (!strcmp(name, "inside-sphere")) {
        const float center[3] = {0, 0, 0};
        m = meshgen_uv_sphere(center, 1.0f, 512, 256);
        mesh.num_vertices = m.num_vertices;
        mesh.positions = m.positions;
        mesh.normals = m.normals;
        mesh.num_indices = 3 * m.num_triangles;
        mesh.indices = m.indices;
        v = &sphere_view;
    } else {
        fprintf(stderr, "testtool: unknown scene '%s'\n", name);
        return 2;
    }
    cam.yfov = (float)v->yfov;
    for (int k = 0; k < 3; k++)
        nodes[1].translation[k] = (float)v->eye[k];
    quat(v, nodes[1].rotation);
    ok = gltf_write_file(out, &d);
    meshgen_destroy(&m);
    return ok ? 0 : 1;
}

/* Analytic hit along the ray through the centre of pixel (x, y): distance t and the
 * normal seen by the ray (facing it). False on a miss. */
static int trace(const char *name, const double o[3], const double d[3], double *t, double n[3])
{
    if (!strcmp(name, "plane")) {
        double c[3] = {0, 0, -1}, dn = 0, cn = 0;
        for (int k = 0; k < 3; k++) {
            dn += d[k] * plane_n[k];
            cn += (c[k] - o[k]) * plane_n[k];
        }
        if (dn == 0 || cn / dn <= 0)
            return 0;
        *t = cn / dn;
        for (int k = 0; k < 3; k++)
            n[k] = dn < 0 ? plane_n[k] : -plane_n[k];
        return 1;
    }
    /* unit sphere at the origin, seen from inside: t = -b + sqrt(b^2 - c) */
    double b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
    double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - 1.0;
    *t = -b + sqrt(b * b - c);
    for (int k = 0; k < 3; k++)
        n[k] = -(o[k] + *t * d[k]); /* inward: the side the camera sees */
    return 1;
}

static int write_ref(const char *name, const char *aov, int w, int h, const char *out, double shift)
{
    static const char *const names[] = {"R", "G", "B", "A"};
    const view *v = !strcmp(name, "plane") ? &plane_view : &sphere_view;
    double right[3], up[3], fwd[3], th = tan(0.5 * v->yfov), aspect = (double)w / h;
    image img;
    bool depth = !strcmp(aov, "depth");
    if (strcmp(name, "plane") && strcmp(name, "inside-sphere")) {
        fprintf(stderr, "testtool: unknown scene '%s'\n", name);
        return 2;
    }
    basis(v, right, up, fwd);
    image_create(&img, w, h, 4, names);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double sx = (2.0 * (x + 0.5 + shift) / w - 1.0) * th * aspect, sy = (1.0 - 2.0 * (y + 0.5) / h) * th;
            double d[3], len = 0, t, n[3], val[3];
            for (int k = 0; k < 3; k++) {
                d[k] = fwd[k] + sx * right[k] + sy * up[k];
                len += d[k] * d[k];
            }
            for (int k = 0; k < 3; k++)
                d[k] /= sqrt(len);
            if (trace(name, v->eye, d, &t, n)) {
                double dz = d[0] * fwd[0] + d[1] * fwd[1] + d[2] * fwd[2];
                for (int k = 0; k < 3; k++)
                    val[k] = depth ? t * dz : n[k];
                img.planes[3][y * w + x] = 1;
            } else {
                val[0] = val[1] = val[2] = 0;
            }
            for (int k = 0; k < 3; k++)
                img.planes[k][y * w + x] = (float)val[k];
        }
    {
        bool ok = image_write_exr(&img, out, NULL, 0);
        image_destroy(&img);
        return ok ? 0 : 1;
    }
}

/* Statistics of a rendered EXR for the shell tests: pixels covered (A > 0.5), the mean
 * luminance over them and over the whole image, and the box of the "red" pixels (R > 0.5,
 * G and B < 0.25; -1s when none), NaN or infinite values: `covered N mean L image-mean L
 * red X0 Y0 X1 Y1 nonfinite N`. */
static int stats(const char *path)
{
    image img;
    if (!image_read_exr(&img, path))
        return 1;
    int r = image_channel(&img, "R"), g = image_channel(&img, "G"), b = image_channel(&img, "B"),
        a = image_channel(&img, "A");
    if (r < 0 || g < 0 || b < 0 || a < 0) {
        fprintf(stderr, "testtool: %s has no R, G, B, A\n", path);
        image_destroy(&img);
        return 1;
    }
    long covered = 0, nonfinite = 0;
    double sum = 0, all = 0;
    int box[4] = {-1, -1, -1, -1};
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            size_t i = (size_t)y * img.width + x;
            double R = img.planes[r][i], G = img.planes[g][i], B = img.planes[b][i];
            double lum = 0.2126 * R + 0.7152 * G + 0.0722 * B;
            nonfinite += !isfinite(R) + !isfinite(G) + !isfinite(B);
            all += lum;
            if (img.planes[a][i] > 0.5f) {
                covered++;
                sum += lum;
            }
            if (R > 0.5 && G < 0.25 && B < 0.25) {
                if (box[0] < 0 || x < box[0]) box[0] = x;
                if (box[1] < 0 || y < box[1]) box[1] = y;
                if (x > box[2]) box[2] = x;
                if (y > box[3]) box[3] = y;
            }
        }
    printf("covered %ld mean %.6g image-mean %.6g red %d %d %d %d nonfinite %ld\n", covered,
           covered ? sum / covered : 0.0, all / ((double)img.width * img.height), box[0], box[1], box[2], box[3],
           nonfinite);
    image_destroy(&img);
    return 0;
}

/* Checks a depth or normal PNG of gonio render against the documented mapping applied to
 * an analytic reference (from `ref`, all pixels covered): depth: 255 (1 - 0.8 t) with
 * t = (z - zmin) / (zmax - zmin) over the reference's range; normal: 255 (0.5 n + 0.5).
 * Passes when every channel of every pixel is within one code value. */
static int check_png(const char *what, const char *png, const char *ref_path)
{
    image ref;
    uint8_t *px;
    int w, h, bad = 0;
    double zmin = INFINITY, zmax = -INFINITY;
    if (!image_read_exr(&ref, ref_path))
        return 1;
    if (!image_read_png(png, &px, &w, &h)) {
        image_destroy(&ref);
        return 1;
    }
    if (w != ref.width || h != ref.height) {
        fprintf(stderr, "%s: %dx%d, the reference %dx%d\n", png, w, h, ref.width, ref.height);
        bad = 1;
    }
    {
        /* Channels come back sorted by name (A, B, G, R): look them up. */
        const float *rgb[3] = {NULL, NULL, NULL};
        static const char *const names[3] = {"R", "G", "B"};
        for (int k = 0; k < 3 && !bad; k++) {
            int c = image_channel(&ref, names[k]);
            if (c < 0) {
                fprintf(stderr, "%s: no channel %s\n", ref_path, names[k]);
                bad = 1;
            } else {
                rgb[k] = ref.planes[c];
            }
        }
        for (int i = 0; !bad && i < w * h; i++) {
            zmin = fmin(zmin, rgb[0][i]);
            zmax = fmax(zmax, rgb[0][i]);
        }
        if (!bad && !strcmp(what, "depth") && !(zmax > zmin)) {
            fprintf(stderr, "%s: the reference depth is constant\n", ref_path);
            bad = 1;
        }
        for (int i = 0; !bad && i < w * h; i++)
            for (int k = 0; k < 3; k++) {
                double want = !strcmp(what, "depth") ? 255 * (1 - 0.8 * (rgb[0][i] - zmin) / (zmax - zmin))
                                                     : 255 * (0.5 * rgb[k][i] + 0.5);
                if (!(fabs(px[4 * i + k] - want) <= 1)) {
                    fprintf(stderr, "%s: pixel %d channel %d is %d, expected %.1f\n", png, i, k, px[4 * i + k], want);
                    bad = 1;
                    break;
                }
            }
    }
    free(px);
    image_destroy(&ref);
    return bad;
}

/* Copies channel `from` of an EXR into a one-channel EXR as "R" (to compare it with gonio diff). */
static int pick_channel(const char *in, const char *from, const char *out)
{
    image a, b;
    const char *names[] = {"R"};
    int c;
    bool ok;
    if (!image_read_exr(&a, in))
        return 1;
    if ((c = image_channel(&a, from)) < 0) {
        fprintf(stderr, "%s: no channel %s\n", in, from);
        image_destroy(&a);
        return 1;
    }
    image_create(&b, a.width, a.height, 1, names);
    memcpy(b.planes[0], a.planes[c], sizeof(float) * (size_t)a.width * (size_t)a.height);
    ok = image_write_exr(&b, out, NULL, 0);
    image_destroy(&a);
    image_destroy(&b);
    return ok ? 0 : 1;
}

/* IN.exr -> OUT.exr with channels renamed or dropped: SPEC is "OLD=NEW,OLD2=,..." (an
 * empty NEW drops the channel): other renderers' layer names, files without a beauty. */
static int rename_channels(const char *in, const char *out, const char *spec)
{
    image a;
    char buf[1024], *tok, *save;
    bool ok;
    if (!image_read_exr(&a, in))
        return 1;
    snprintf(buf, sizeof buf, "%s", spec);
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        int c;
        if (!eq || (*eq = 0, (c = image_channel(&a, tok)) < 0) || strlen(eq + 1) >= sizeof a.names[0]) {
            fprintf(stderr, "%s: bad rename '%s' (no such channel, or no '=')\n", in, tok);
            image_destroy(&a);
            return 1;
        }
        if (eq[1])
            strcpy(a.names[c], eq + 1);
        else
            image_remove_channel(&a, c);
    }
    ok = image_write_exr(&a, out, NULL, 0);
    image_destroy(&a);
    return ok ? 0 : 1;
}

/* IN.exr -> OUT.exr with channel `name` of pixel (x, y) set to value ("nan", "inf" too). */
static int poke_value(const char *in, const char *name, int x, int y, const char *value, const char *out)
{
    image a;
    int c;
    bool ok;
    if (!image_read_exr(&a, in))
        return 1;
    c = image_channel(&a, name);
    if (c < 0 || x < 0 || y < 0 || x >= a.width || y >= a.height) {
        fprintf(stderr, "%s: no channel %s or pixel (%d, %d)\n", in, name, x, y);
        image_destroy(&a);
        return 1;
    }
    a.planes[c][(size_t)y * a.width + x] = strtof(value, NULL);
    ok = image_write_exr(&a, out, NULL, 0);
    image_destroy(&a);
    return ok ? 0 : 1;
}

/* The denoiser's figures (tests/denoise/quality.sh) of TEST.exr's R, G, B against REF.exr:
 * "rmse X corrected X display X display-corrected X mean X ref-noise X": the RMSE in linear
 * RGB; the same less the reference's own noise (the mean of its variance.R/G/B channels,
 * when it has them: sqrt(max(0, rmse^2 - noise^2))); the RMSE of both clamped to [0, 1]
 * (what the default PNG shows before its sRGB curve), and the same less the noise of the
 * reference's values below 1 (clamping leaves those as they are and flattens the rest);
 * mean(TEST) / mean(REF) - 1; and the reference's noise. */
static int denoise_errors(const char *test, const char *refp)
{
    static const char *const rgb[3] = {"R", "G", "B"}, *const var[3] = {"variance.R", "variance.G", "variance.B"};
    image a, b;
    double se = 0, sd = 0, ma = 0, mb = 0, noise = 0, noise_d = 0;
    int rc = 1;
    if (!image_read_exr(&a, test))
        return 1;
    if (!image_read_exr(&b, refp)) {
        image_destroy(&a);
        return 1;
    }
    size_t n = (size_t)a.width * (size_t)a.height;
    if (a.width != b.width || a.height != b.height) {
        fprintf(stderr, "%s and %s differ in size\n", test, refp);
        goto done;
    }
    for (int c = 0; c < 3; c++) {
        int ca = image_channel(&a, rgb[c]), cb = image_channel(&b, rgb[c]), cv = image_channel(&b, var[c]);
        if (ca < 0 || cb < 0) {
            fprintf(stderr, "no channel %s in %s or %s\n", rgb[c], test, refp);
            goto done;
        }
        for (size_t p = 0; p < n; p++) {
            double x = a.planes[ca][p], y = b.planes[cb][p];
            double xd = fmin(fmax(x, 0.0), 1.0), yd = fmin(fmax(y, 0.0), 1.0);
            se += (x - y) * (x - y);
            sd += (xd - yd) * (xd - yd);
            ma += x;
            mb += y;
            noise += cv >= 0 ? b.planes[cv][p] : 0.0;
            /* Clamped, a value well below 1 keeps its noise, one above loses it (nearly all). */
            noise_d += cv >= 0 && y < 1.0 ? b.planes[cv][p] : 0.0;
        }
    }
    se /= 3.0 * (double)n;
    sd /= 3.0 * (double)n;
    noise /= 3.0 * (double)n;
    noise_d /= 3.0 * (double)n;
    printf("rmse %.6f corrected %.6f display %.6f display-corrected %.6f mean %+.6f ref-noise %.6f\n", sqrt(se),
           sqrt(fmax(0.0, se - noise)), sqrt(sd), sqrt(fmax(0.0, sd - noise_d)), ma / mb - 1, sqrt(noise));
    rc = 0;
done:
    image_destroy(&a);
    image_destroy(&b);
    return rc;
}

/* The value of channel `name` at each pixel (x, y) of xy (n pairs), a line each: one read of
 * the file for the many pixels a probe checks. */
static int print_values(const char *in, const char *name, char **xy, int n)
{
    image a;
    int c, rc = 0;
    if (!image_read_exr(&a, in))
        return 1;
    c = image_channel(&a, name);
    for (int i = 0; i < n && rc == 0; i++) {
        int x = atoi(xy[2 * i]), y = atoi(xy[2 * i + 1]);
        if (c < 0 || x < 0 || y < 0 || x >= a.width || y >= a.height) {
            fprintf(stderr, "%s: no channel %s or pixel (%d, %d)\n", in, name, x, y);
            rc = 1;
        } else {
            printf("%.9g\n", a.planes[c][(size_t)y * (size_t)a.width + (size_t)x]);
        }
    }
    image_destroy(&a);
    return rc;
}

/* Per channel of R, G, B over the whole image: the mean and the centroid's x (the
 * value-weighted mean column; -1 for a black channel), for the volume tests:
 * `mean R G B cx R G B`, %.9g. */
static int rgb_stats(const char *path)
{
    image img;
    const char *names[3] = {"R", "G", "B"};
    double mean[3], cx[3];
    if (!image_read_exr(&img, path))
        return 1;
    for (int k = 0; k < 3; k++) {
        int c = image_channel(&img, names[k]);
        double sum = 0, sx = 0;
        if (c < 0) {
            fprintf(stderr, "testtool: %s has no channel %s\n", path, names[k]);
            image_destroy(&img);
            return 1;
        }
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++) {
                double v = img.planes[c][(size_t)y * img.width + x];
                sum += v;
                sx += v * x;
            }
        mean[k] = sum / ((double)img.width * img.height);
        cx[k] = sum > 0 ? sx / sum : -1;
    }
    printf("mean %.9g %.9g %.9g cx %.9g %.9g %.9g\n", mean[0], mean[1], mean[2], cx[0], cx[1], cx[2]);
    image_destroy(&img);
    return 0;
}

/* The spread of an image's light: the luminance-weighted second central moments of the
 * pixel coordinates, `sxx syy sxy` (%.6g; x right, y down), for the anisotropy tests. */
static int moments(const char *path)
{
    image img;
    if (!image_read_exr(&img, path))
        return 1;
    int r = image_channel(&img, "R"), g = image_channel(&img, "G"), b = image_channel(&img, "B");
    if (r < 0 || g < 0 || b < 0) {
        fprintf(stderr, "testtool: %s has no R, G, B\n", path);
        image_destroy(&img);
        return 1;
    }
    double w = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            size_t i = (size_t)y * img.width + x;
            double l = 0.2126 * img.planes[r][i] + 0.7152 * img.planes[g][i] + 0.0722 * img.planes[b][i];
            if (!(l > 0))
                continue;
            w += l;
            sx += l * x;
            sy += l * y;
            sxx += l * x * x;
            syy += l * y * y;
            sxy += l * x * y;
        }
    image_destroy(&img);
    if (!(w > 0)) {
        fprintf(stderr, "testtool: %s is black\n", path);
        return 1;
    }
    double mx = sx / w, my = sy / w;
    printf("%.6g %.6g %.6g\n", sxx / w - mx * mx, syy / w - my * my, sxy / w - mx * my);
    return 0;
}

/* PART's pixels sit at (x0, y0) of the display window (image.h); so do WHOLE's. */
static int same_bits(const char *whole, const char *part)
{
    image a, b;
    long differ = 0, compared = 0;
    int rc = 1;
    if (!image_read_exr(&a, whole))
        return 1;
    if (!image_read_exr(&b, part)) {
        image_destroy(&a);
        return 1;
    }
    for (int c = 0; c < b.num_channels; c++) {
        int ca = image_channel(&a, b.names[c]);
        if (!strncmp(b.names[c], "sum", 3))
            continue;
        if (ca < 0) {
            fprintf(stderr, "%s: no channel %s (which %s has)\n", whole, b.names[c], part);
            goto done;
        }
        for (int y = 0; y < b.height; y++)
            for (int x = 0; x < b.width; x++) {
                int ax = b.x0 + x - a.x0, ay = b.y0 + y - a.y0;
                const float *vb = &b.planes[c][(size_t)y * b.width + x], *va;
                if (ax < 0 || ay < 0 || ax >= a.width || ay >= a.height) {
                    fprintf(stderr, "%s: pixel (%d, %d) is outside %s\n", part, b.x0 + x, b.y0 + y, whole);
                    goto done;
                }
                va = &a.planes[ca][(size_t)ay * a.width + ax];
                compared++;
                if (memcmp(va, vb, sizeof *va)) {
                    if (!differ)
                        fprintf(stderr, "first difference: %s at (%d, %d): %.9g vs %.9g\n", b.names[c],
                                b.x0 + x, b.y0 + y, *va, *vb);
                    differ++;
                }
            }
    }
    printf("%ld of %ld values differ\n", differ, compared);
    rc = differ || !compared;
done:
    image_destroy(&a);
    image_destroy(&b);
    return rc;
}

/* Decodes ENCODED (WebP or KTX2) through image_decode, the loader's decoder, and compares
 * its texels with REF.png's, read by libpng: the largest difference and the RMSE over the
 * channels listed (e.g. RGBA, RG), in 8-bit steps. Exit 1 above either bound. */
static int texels(const char *encoded, const char *ref, const char *channels, double max_err, double max_rmse)
{
    size_t n = 0;
    uint8_t *bytes = util_read_file(encoded, &n), *dec = NULL, *px = NULL;
    uint32_t w = 0, h = 0;
    int rw = 0, rh = 0, rc = 1;
    char why[512];
    if (!bytes)
        return 1;
    if (image_decode(bytes, n, NULL, UINT64_MAX, &dec, &w, &h, why, sizeof why) != IMAGE_DECODED) {
        fprintf(stderr, "%s: %s\n", encoded, why);
        goto done;
    }
    if (!image_read_png(ref, &px, &rw, &rh) || (uint32_t)rw != w || (uint32_t)rh != h) {
        fprintf(stderr, "%s: unreadable, or not %ux%u\n", ref, w, h);
        goto done;
    }
    double sum = 0, worst = 0;
    size_t count = 0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (const char *c = channels; *c; c++) {
            int k = (int)(strchr("RGBA", *c) ? strchr("RGBA", *c) - "RGBA" : 0);
            double d = fabs((double)dec[4 * i + k] - px[4 * i + k]);
            sum += d * d;
            worst = d > worst ? d : worst;
            count++;
        }
    double rmse = count ? sqrt(sum / count) : 0;
    printf("%s: %ux%u, %s: max error %g, rmse %.3f (of 255)\n", encoded, w, h, channels, worst, rmse);
    rc = worst > max_err || rmse > max_rmse;
done:
    free(bytes);
    free(dec);
    free(px);
    return rc;
}

/* ktx2.cpp: IN.png encoded by Basis Universal's encoder into OUT.ktx2. */
int tool_ktx2(const char *mode, const char *in, const char *out, bool rg);

/* compress.cpp: IN.gltf encoded with Draco or meshoptimizer, losslessly, into OUT.gltf. */
int tool_compress(const char *how, const char *in, const char *out);

/* sheen_table.c: glsl/lib/sheen_albedo.h on stdout. */
int sheen_table(void);

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "sheen-table"))
        return sheen_table();
    if (argc == 4 && !strcmp(argv[1], "same"))
        return same_bits(argv[2], argv[3]);
    if (argc == 3 && !strcmp(argv[1], "stats"))
        return stats(argv[2]);
    if (argc == 3 && !strcmp(argv[1], "rgb"))
        return rgb_stats(argv[2]);
    if (argc == 3 && !strcmp(argv[1], "moments"))
        return moments(argv[2]);
    if (argc >= 6 && argc % 2 == 0 && !strcmp(argv[1], "at"))
        return print_values(argv[2], argv[3], argv + 4, (argc - 4) / 2);
    if (argc == 5 && !strcmp(argv[1], "png") && (!strcmp(argv[2], "depth") || !strcmp(argv[2], "normal")))
        return check_png(argv[2], argv[3], argv[4]);
    if (argc == 4 && !strcmp(argv[1], "png")) { /* IN.exr -> OUT.png as render --png writes it */
        image a;
        bool ok = image_read_exr(&a, argv[2]) && image_write_png_from(&a, argv[3], 0.0f, IMAGE_TONEMAP_CLAMP);
        image_destroy(&a);
        return ok ? 0 : 1;
    }
    if (argc == 4 && !strcmp(argv[1], "errors"))
        return denoise_errors(argv[2], argv[3]);
    if (argc == 5 && !strcmp(argv[1], "rename"))
        return rename_channels(argv[2], argv[3], argv[4]);
    if (argc == 8 && !strcmp(argv[1], "poke"))
        return poke_value(argv[2], argv[3], atoi(argv[4]), atoi(argv[5]), argv[6], argv[7]);
    if (argc == 5 && !strcmp(argv[1], "pick"))
        return pick_channel(argv[2], argv[3], argv[4]);
    if (argc == 5 && !strcmp(argv[1], "compress") && (!strcmp(argv[2], "draco") || !strcmp(argv[2], "meshopt")))
        return tool_compress(argv[2], argv[3], argv[4]);
    if ((argc == 5 || argc == 6) && !strcmp(argv[1], "ktx2"))
        return tool_ktx2(argv[2], argv[3], argv[4], argc == 6 && !strcmp(argv[5], "rg"));
    if (argc == 7 && !strcmp(argv[1], "texels"))
        return texels(argv[2], argv[3], argv[4], atof(argv[5]), atof(argv[6]));
    if (argc == 4 && !strcmp(argv[1], "scene"))
        return write_scene(argv[2], argv[3]);
    if ((argc == 7 || argc == 8) && !strcmp(argv[1], "ref"))
        return write_ref(argv[2], argv[3], atoi(argv[4]), atoi(argv[5]), argv[6],
                         argc == 8 ? atof(argv[7]) : 0.0);
    fprintf(stderr, "usage: testtool scene NAME OUT.gltf | testtool compress draco|meshopt IN.gltf OUT.gltf | testtool ref NAME depth|normal W H OUT.exr\n"
                    "       testtool png depth|normal PNG REF.exr | testtool pick IN.exr CHANNEL OUT.exr\n"
                    "       testtool at IN.exr CHANNEL X Y [X Y...] | testtool same WHOLE.exr PART.exr | testtool rgb IN.exr\n"
                    "       testtool moments IN.exr | testtool rename IN.exr OUT.exr OLD=NEW,OLD2=,...\n"
                    "       testtool poke IN.exr CHANNEL X Y VALUE OUT.exr | testtool errors TEST.exr REF.exr\n"
                    "       testtool png IN.exr OUT.png\n"
                    "       testtool ktx2 etc1s|uastc|uastc-zstd IN.png OUT.ktx2 [rg]\n"
                    "       testtool texels IMAGE.webp|.ktx2 REF.png CHANNELS MAX_ERR MAX_RMSE\n"
                    "       testtool sheen-table\n");
    return 2;
}
