/* preview.c: `gonio preview`: a GLFW window in which the render converges live. Each frame
 * records a few sample passes of the renderer's kernels (as many as fit in about 1/30 s, so
 * the window stays responsive), tonemaps the accumulation with glsl/kernels/display.comp into a
 * host-visible buffer of 8-bit texels and copies that into the swapchain image. The camera
 * orbits a target (spherical coordinates around the world's +Y), pans in the view plane and
 * flies; any change restarts the accumulation. */
#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "camera.h"
#include "cli.h"
#include "denoise.h"
#include "environment.h"
#include "display.h" /* spv_display: glsl/kernels/display.comp compiled by the build */
#include "image.h"
#include "preview_denoise.h"
#include "render_output.h"
#include "render.h"
#include "scene.h"
#include "util.h"

_Static_assert(IMAGE_TONEMAP_CLAMP == GN_TONEMAP_CLAMP && IMAGE_TONEMAP_ACES == GN_TONEMAP_ACES &&
                   IMAGE_TONEMAP_REINHARD == GN_TONEMAP_REINHARD, "tonemap values (shared.h)");

#define PREVIEW_FRAME_SECONDS (1.0 / 30) /* GPU time per frame the pass batch aims at */
#define PREVIEW_MAX_BATCH 64             /* passes per frame at most */
#define PREVIEW_IDLE_SECONDS 0.05        /* event wait once converged: repaints, not spins */
#define PREVIEW_DENOISE_FIRST_SPP 8      /* the denoised view's first image; then at 2x, 4x, ... */

GN_STATIC_ASSERT(GN_MODE_COUNT <= 9, "a number key per mode");
static const char keys_help_rest[] =
    "  left mouse          orbit around the target\n"
    "  right/middle mouse  pan\n"
    "  wheel               zoom (towards the target)\n"
    "  W A S D / Q E       fly forward, left, back, right / down, up\n"
    "  C                   next glTF camera (then the framing camera)\n"
    "  R                   reset the camera\n"
    "  + / -               exposure up / down by half a stop\n"
    "  T                   next tonemap (clamp, reinhard, aces)\n"
    "  N                   denoised view on/off (path mode; OIDN, as render --denoise):\n"
    "                      denoised at 8 spp, then each time the samples double\n"
    "  P                   write the accumulated image as EXR and PNG\n"
    "  H                   this help\n"
    "  Esc                 quit\n";

/* The keys' help: the number keys are the modes in GN_MODES order. */
static const char *keys_help(void)
{
    static char help[2048];
    if (!help[0])
        snprintf(help, sizeof help, "gonio preview keys:\n  1..%u                mode: %s\n%s", (unsigned)GN_MODE_COUNT,
                 render_mode_list(), keys_help_rest);
    return help;
}

typedef struct preview {
    scene sc;
    gpu g;
    renderer r;
    render_settings s;
    GLFWwindow *window;
    VkSurfaceKHR surface;
    VkSurfaceFormatKHR format;
    VkPresentModeKHR present_mode;
    VkSwapchainKHR swapchain;
    VkExtent2D extent;
    int fb_width, fb_height;       /* the window's size when the swapchain was made */
    bool stale;                    /* the swapchain no longer fits the window */
    uint32_t num_images;
    VkImage *images;
    VkSemaphore acquired, *presentable; /* presentable: one per image, as present waits on it */
    VkFence fence;
    VkCommandBuffer cmd;
    gpu_pipeline display;
    gpu_buffer texels;             /* what the window shows, packed as the swapchain's texels */
    int display_width, display_height;
    bool shown;                    /* texels hold a displayed frame */

    /* Camera: the start camera until the user moves it, then the orbit below. */
    int start_camera;
    const scene_camera *start_view; /* --look-at or --camera FILE.exr, else NULL */
    bool moved;
    GnCamera cam;
    float target[3], distance, yaw, pitch, radius;
    double mouse_x, mouse_y;

    int spp, max_spp, batch;       /* samples accumulated, the limit (0: none), passes/frame */
    bool restart, save, redraw, quit_key; /* redraw: the display changed, not the samples */
    bool failed; /* an error was reported: the window closes, exit status 1 */
    float exposure;
    image_tonemap tonemap;
    const char *prefix;
    double paths_per_second, frame_seconds;
    char title[256];

    /* The denoised view (N, --denoise): made on preview_denoise's thread from the
     * accumulation at PREVIEW_DENOISE_FIRST_SPP spp and each doubling after, shown through the
     * display kernel from `denoised` (RGBA means, so inv_spp 1). A restart bumps generation,
     * so a result of an older accumulation is dropped. */
    bool denoise_view, denoise_unavailable;
    preview_denoiser denoiser;
    unsigned generation;
    int denoised_spp, denoise_next; /* shown (0: none yet); the spp of the next job */
    double denoise_seconds;
    gpu_buffer denoised;
    gpu_pipeline display_denoised;
} preview;

/* ---- camera ----------------------------------------------------------------------------- */

static void vec_axpy(float *y, float a, const float *x)
{
    for (int k = 0; k < 3; k++)
        y[k] += a * x[k];
}

/* The orbit state that reproduces the current (or start) camera: the target is where the
 * view axis passes the scene's centre. */
static bool camera_start(preview *p)
{
    const float *lo = p->sc.bounds_min, *hi = p->sc.bounds_max;
    float c[3], d = 0, f[3];
    p->s.camera_override = NULL;
    p->moved = false;
    if (!renderer_camera(&p->r, &p->s, &p->cam))
        return false;
    memcpy(f, &p->cam.forward, sizeof f);
    p->radius = 0;
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5f * (lo[k] + hi[k]);
        p->radius += 0.25f * (hi[k] - lo[k]) * (hi[k] - lo[k]);
        d += (c[k] - (&p->cam.position.x)[k]) * f[k];
    }
    p->radius = fmaxf(sqrtf(p->radius), 1e-3f);
    p->distance = d > 1e-3f * p->radius ? d : p->radius;
    memcpy(p->target, &p->cam.position, sizeof p->target);
    vec_axpy(p->target, p->distance, f);
    p->yaw = atan2f(f[0], f[2]);
    p->pitch = asinf(fmaxf(-1.0f, fminf(1.0f, f[1])));
    return true;
}

/* Applies the orbit state to the camera and restarts the accumulation. */
static void camera_moved(preview *p)
{
    const float lim = 1.55f; /* just short of straight up or down, where yaw is undefined */
    float f[3], rt[3], len;
    p->pitch = fmaxf(-lim, fminf(lim, p->pitch));
    p->distance = fmaxf(p->distance, 1e-4f * p->radius);
    f[0] = cosf(p->pitch) * sinf(p->yaw);
    f[1] = sinf(p->pitch);
    f[2] = cosf(p->pitch) * cosf(p->yaw);
    len = sqrtf(f[2] * f[2] + f[0] * f[0]);
    rt[0] = -f[2] / len; /* forward x world up */
    rt[1] = 0;
    rt[2] = f[0] / len;
    p->cam.forward = (vec3){f[0], f[1], f[2]};
    p->cam.right = (vec3){rt[0], rt[1], rt[2]};
    p->cam.up = (vec3){rt[1] * f[2] - rt[2] * f[1], rt[2] * f[0] - rt[0] * f[2],
                       rt[0] * f[1] - rt[1] * f[0]};
    memcpy(&p->cam.position, p->target, sizeof p->target);
    vec_axpy(&p->cam.position.x, -p->distance, f);
    p->s.camera_override = &p->cam;
    p->moved = true;
    p->restart = true;
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    preview *p = glfwGetWindowUserPointer(w);
    float dx = (float)(x - p->mouse_x), dy = (float)(y - p->mouse_y);
    p->mouse_x = x;
    p->mouse_y = y;
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
        /* The scene follows the mouse: dragging right turns the camera left around it. */
        p->yaw -= 0.005f * dx;
        p->pitch -= 0.005f * dy;
        camera_moved(p);
    } else if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
               glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
        /* World units per pixel at the target's distance, so the target stays under the cursor. */
        float k = 2 * p->distance * p->cam.tan_half_fovy / (float)(p->extent.height ? p->extent.height : 1);
        if (!p->moved)
            camera_moved(p);
        vec_axpy(p->target, -k * dx, &p->cam.right.x);
        vec_axpy(p->target, k * dy, &p->cam.up.x);
        camera_moved(p);
    }
}

static void on_scroll(GLFWwindow *w, double xoff, double yoff)
{
    preview *p = glfwGetWindowUserPointer(w);
    (void)xoff;
    p->distance *= powf(0.85f, (float)yoff);
    camera_moved(p);
}

/* WASD/QE while held, at half the scene's radius per second. */
static void fly(preview *p, float dt)
{
    static const float world_up[3] = {0, 1, 0};
    const struct { int key; const float *axis; float sign; } keys[] = {
        {GLFW_KEY_W, &p->cam.forward.x, 1}, {GLFW_KEY_S, &p->cam.forward.x, -1},
        {GLFW_KEY_D, &p->cam.right.x, 1},   {GLFW_KEY_A, &p->cam.right.x, -1},
        {GLFW_KEY_E, world_up, 1},          {GLFW_KEY_Q, world_up, -1},
    };
    bool any = false;
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++) {
        if (glfwGetKey(p->window, keys[i].key) == GLFW_PRESS) {
            if (!p->moved)
                camera_moved(p); /* the orbit basis, so a rolled start camera moves sensibly */
            vec_axpy(p->target, keys[i].sign * 0.5f * p->radius * dt, keys[i].axis);
            any = true;
        }
    }
    if (any)
        camera_moved(p);
}

/* ---- keys and output files -------------------------------------------------------------- */

static void denoise_toggle(preview *p);

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    preview *p = glfwGetWindowUserPointer(w);
    (void)scancode;
    (void)mods;
    if (action == GLFW_RELEASE)
        return;
    if (key >= GLFW_KEY_1 && key < GLFW_KEY_1 + (int)GN_MODE_COUNT) {
        uint32_t m = (uint32_t)(key - GLFW_KEY_1);
        if (m != p->s.mode) {
            p->s.mode = m;
            p->restart = true;
        }
        return;
    }
    switch (key) {
    case GLFW_KEY_ESCAPE: p->quit_key = true; break;
    case GLFW_KEY_C:
        p->s.view = NULL;
        p->s.camera = p->s.camera + 1 < (int)p->sc.num_cameras ? p->s.camera + 1 : -1;
        camera_start(p);
        p->restart = true;
        if (p->s.camera < 0)
            util_info("camera: framing the scene");
        else
            util_info("camera %d: %s", p->s.camera, p->sc.cameras[p->s.camera].name);
        break;
    case GLFW_KEY_R:
        p->s.camera = p->start_camera;
        p->s.view = p->start_view;
        camera_start(p);
        p->restart = true;
        break;
    case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD: p->exposure += 0.5f; p->redraw = true; break;
    case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT: p->exposure -= 0.5f; p->redraw = true; break;
    case GLFW_KEY_T: p->tonemap = (image_tonemap)((p->tonemap + 1) % 3); p->redraw = true; break;
    case GLFW_KEY_N: denoise_toggle(p); break;
    case GLFW_KEY_P: p->save = true; break;
    case GLFW_KEY_H: fputs(keys_help(), stdout); fflush(stdout); break;
    default: break;
    }
}

/* ---- the denoised view ------------------------------------------------------------------ */

/* N: the view on or off. Turning it on the first time loads the library (a message and the
 * noisy view when it is missing) and, when the render lacks the guides, restarts it with
 * them. */
static void denoise_toggle(preview *p)
{
    if (!p->denoise_view && !p->denoiser.started) {
        if (p->denoise_unavailable || !denoise_load() || !preview_denoiser_start(&p->denoiser)) {
            p->denoise_unavailable = true; /* said why */
            p->redraw = true;
            return;
        }
    }
    p->denoise_view = !p->denoise_view;
    if (p->denoise_view && (p->s.aov & (RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL)) != (RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL)) {
        p->s.aov |= RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL;
        p->restart = true;
    }
    p->redraw = true;
}

/* After the frame's fence: collects a finished denoise into `denoised`, and hands the
 * accumulation to the thread when it has reached denoise_next samples (or its last). */
static void denoise_step(preview *p)
{
    float *rgba;
    int w, h, spp;
    unsigned generation;
    double seconds;
    bool ok;
    if (!p->denoiser.started)
        return;
    if (preview_denoiser_take(&p->denoiser, &rgba, &w, &h, &spp, &generation, &seconds, &ok)) {
        if (!ok) {
            p->denoise_view = false;
            p->denoise_unavailable = true;
        } else if (generation == p->generation && w == p->r.accum.width && h == p->r.accum.height &&
                   p->denoised.size >= 16 * (VkDeviceSize)w * (VkDeviceSize)h) {
            memcpy(p->denoised.mapped, rgba, 16 * (size_t)w * (size_t)h);
            p->denoised_spp = spp;
            p->denoise_seconds = seconds;
            p->redraw = true;
        }
        free(rgba);
    }
    /* A restart pending (the guides just asked for among others): the buffers are the old
     * render's, which may lack them. */
    if (!p->denoise_view || p->restart || p->s.mode != GN_MODE_PATH || p->spp == 0 ||
        preview_denoiser_busy(&p->denoiser) || !(p->s.aov & RENDER_AOV_ALBEDO))
        return;
    if (p->spp >= p->denoise_next || (p->max_spp > 0 && p->spp >= p->max_spp && p->spp > p->denoised_spp)) {
        image img = {0};
        renderer_resolve(&p->r, p->spp, RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL, &img);
        preview_denoiser_submit(&p->denoiser, &img, p->spp, p->generation);
        while (p->denoise_next <= p->spp)
            p->denoise_next *= 2;
    }
}

/* Whether the window shows the denoised image now. */
static bool denoise_shown(const preview *p)
{
    return p->denoise_view && p->denoised_spp > 0 && p->s.mode == GN_MODE_PATH;
}

/* PREFIX-NNN.exr and .png with the first NNN for which neither exists. */
static bool save_accumulated(preview *p)
{
    char exr[4096], png[4096];
    image img = {0};
    bool ok;
    /* The header gonio render writes (its identity, so P's files merge with renders, and the
     * view, so --camera FILE.exr renders it again). */
    render_header h;
    render_stats st = {.spp = p->spp};
    render_header_build(&h, &p->r, &p->s, &st, NULL, cli_command_line());
    if (p->spp == 0)
        return true;
    for (int n = 1;; n++) {
        snprintf(exr, sizeof exr, "%s-%03d.exr", p->prefix, n);
        snprintf(png, sizeof png, "%s-%03d.png", p->prefix, n);
        if (access(exr, F_OK) != 0 && access(png, F_OK) != 0)
            break;
    }
    if (!util_check_output(exr) || !util_check_output(png))
        return false;
    /* With the guides when the render has them (the denoised view; not while a restart
     * that adds them is pending): gonio denoise reads them. */
    renderer_resolve(&p->r, p->spp, p->restart ? 0u : p->s.aov & (RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL), &img);
    ok = image_write_exr(&img, exr, h.attrs, h.count) &&
         render_write_png(&img, p->s.mode, png, p->exposure, p->tonemap); /* as gonio render's */
    if (ok) {
        printf("gonio: wrote %s and %s (%s, %d spp)\n", exr, png,
               render_mode_name(p->s.mode), p->spp);
        fflush(stdout);
    }
    image_destroy(&img);
    return ok;
}

static bool save_screenshot(preview *p, const char *path)
{
    size_t n = (size_t)p->display_width * (size_t)p->display_height;
    uint8_t *rgba = util_malloc(4 * n);
    bool ok;
    if (!p->shown) {
        util_error("%s: no frame was shown, so there is no screenshot", path);
        free(rgba);
        return false;
    }
    memcpy(rgba, p->texels.mapped, 4 * n);
    if (p->format.format == VK_FORMAT_B8G8R8A8_UNORM || p->format.format == VK_FORMAT_B8G8R8A8_SRGB)
        for (size_t i = 0; i < n; i++) {
            uint8_t t = rgba[4 * i];
            rgba[4 * i] = rgba[4 * i + 2];
            rgba[4 * i + 2] = t;
        }
    ok = image_write_png(path, rgba, p->display_width, p->display_height);
    free(rgba);
    if (ok)
        util_info("screenshot %s (%s, %d spp)", path, render_mode_name(p->s.mode), p->spp);
    return ok;
}

/* ---- window, surface and swapchain ------------------------------------------------------ */

static void glfw_error(int code, const char *msg)
{
    (void)code;
    util_warn("GLFW: %s", msg);
}

/* An 8-bit RGBA or BGRA format: the display kernel writes the bytes and a buffer-to-image
 * copy moves them unconverted, so UNORM and SRGB formats show the same sRGB-encoded values. */
static bool choose_surface(preview *p)
{
    VkPhysicalDevice phys = p->g.physical;
    VkBool32 supported = VK_FALSE;
    uint32_t n = 0;
    VkSurfaceFormatKHR *formats;
    VkPresentModeKHR *modes;
    GPU_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(phys, p->g.queue_family, p->surface, &supported));
    if (!supported) {
        util_error("%s cannot present to this window from its compute queue; try another "
                   "--device (see gonio devices)", p->g.props.deviceName);
        return false;
    }
    GPU_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(phys, p->surface, &n, NULL));
    formats = util_calloc(n ? n : 1, sizeof *formats);
    GPU_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(phys, p->surface, &n, formats));
    p->format.format = VK_FORMAT_UNDEFINED;
    for (uint32_t i = 0; i < n && p->format.format == VK_FORMAT_UNDEFINED; i++) {
        VkFormat f = formats[i].format;
        if (formats[i].colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR &&
            (f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_R8G8B8A8_UNORM ||
             f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_SRGB))
            p->format = formats[i];
    }
    free(formats);
    if (p->format.format == VK_FORMAT_UNDEFINED) {
        util_error("%s: the window offers no 8-bit RGBA/BGRA sRGB swapchain format",
                   p->g.props.deviceName);
        return false;
    }
    /* MAILBOX: no tearing, and presenting never waits for a vertical blank. */
    GPU_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(phys, p->surface, &n, NULL));
    modes = util_calloc(n ? n : 1, sizeof *modes);
    GPU_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(phys, p->surface, &n, modes));
    p->present_mode = VK_PRESENT_MODE_FIFO_KHR;
    for (uint32_t i = 0; i < n; i++)
        if (modes[i] == VK_PRESENT_MODE_MAILBOX_KHR)
            p->present_mode = modes[i];
    free(modes);
    return true;
}

static void destroy_presentable(preview *p)
{
    for (uint32_t i = 0; i < p->num_images; i++)
        vkDestroySemaphore(p->g.device, p->presentable[i], NULL);
    free(p->presentable);
    free(p->images);
    p->presentable = NULL;
    p->images = NULL;
    p->num_images = 0;
}

/* (Re)creates the swapchain for the window's current size; false while it is minimised. */
static bool swapchain_create(preview *p)
{
    VkDevice dev = p->g.device;
    VkSurfaceCapabilitiesKHR caps;
    VkSwapchainCreateInfoKHR sci = {.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    VkSemaphoreCreateInfo semi = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSwapchainKHR old = p->swapchain;
    int fw, fh;

    vkDeviceWaitIdle(dev);
    GPU_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(p->g.physical, p->surface, &caps));
    glfwGetFramebufferSize(p->window, &fw, &fh);
    if (caps.currentExtent.width != UINT32_MAX) {
        sci.imageExtent = caps.currentExtent;
    } else {
        sci.imageExtent.width = (uint32_t)fw;
        sci.imageExtent.height = (uint32_t)fh;
        if (sci.imageExtent.width > caps.maxImageExtent.width)
            sci.imageExtent.width = caps.maxImageExtent.width;
        if (sci.imageExtent.height > caps.maxImageExtent.height)
            sci.imageExtent.height = caps.maxImageExtent.height;
    }
    p->fb_width = fw;
    p->fb_height = fh;
    if (!sci.imageExtent.width || !sci.imageExtent.height || !fw || !fh)
        return false;
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
        util_error("%s: the window's images cannot be copied to (no transfer-dst usage)",
                   p->g.props.deviceName);
        p->failed = true;
        return false;
    }
    sci.surface = p->surface;
    sci.minImageCount = caps.minImageCount + 1;
    if (caps.maxImageCount && sci.minImageCount > caps.maxImageCount)
        sci.minImageCount = caps.maxImageCount;
    sci.imageFormat = p->format.format;
    sci.imageColorSpace = p->format.colorSpace;
    sci.imageArrayLayers = 1;
    sci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    sci.preTransform = caps.currentTransform;
    /* The lowest supported bit: OPAQUE when offered. */
    sci.compositeAlpha = (VkCompositeAlphaFlagBitsKHR)(caps.supportedCompositeAlpha &
                                                       (~caps.supportedCompositeAlpha + 1));
    sci.presentMode = p->present_mode;
    sci.clipped = VK_TRUE;
    sci.oldSwapchain = old;
    GPU_CHECK(vkCreateSwapchainKHR(dev, &sci, NULL, &p->swapchain));
    if (old)
        vkDestroySwapchainKHR(dev, old, NULL);
    destroy_presentable(p);
    p->extent = sci.imageExtent;
    p->stale = false;
    GPU_CHECK(vkGetSwapchainImagesKHR(dev, p->swapchain, &p->num_images, NULL));
    p->images = util_calloc(p->num_images, sizeof *p->images);
    p->presentable = util_calloc(p->num_images, sizeof *p->presentable);
    GPU_CHECK(vkGetSwapchainImagesKHR(dev, p->swapchain, &p->num_images, p->images));
    for (uint32_t i = 0; i < p->num_images; i++)
        GPU_CHECK(vkCreateSemaphore(dev, &semi, NULL, &p->presentable[i]));
    p->restart = true;
    return true;
}

/* ---- frames ----------------------------------------------------------------------------- */

/* After renderer_begin: the texel buffer and the display kernel for the image size (the
 * kernel's descriptors name the renderer's accumulation buffer, reallocated on a resize). */
static void display_resize(preview *p)
{
    gpu_binding b[2] = {{GN_DISPLAY_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &p->r.accum.accum},
                        {GN_DISPLAY_BIND_OUT, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &p->texels}};
    gpu_pipeline_desc pd = {.name = "display", .code = spv_display, .code_size = sizeof spv_display,
                            .local_size = {GN_TILE_X, GN_TILE_Y, 1},
                            .push_size = sizeof(GnDisplayPush), .bindings = b, .num_bindings = 2};
    if (p->display_width == p->r.accum.width && p->display_height == p->r.accum.height &&
        (!p->denoiser.started || p->denoised.buffer))
        return;
    gpu_pipeline_destroy(&p->g, &p->display);
    gpu_buffer_destroy(&p->g, &p->texels);
    gpu_buffer_create(&p->g, &p->texels, 4 * (VkDeviceSize)p->r.accum.width * (VkDeviceSize)p->r.accum.height,
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    gpu_pipeline_create(&p->g, &p->display, &pd);
    gpu_pipeline_destroy(&p->g, &p->display_denoised);
    gpu_buffer_destroy(&p->g, &p->denoised);
    if (p->denoiser.started) { /* the denoised view's input: the display kernel on `denoised` */
        gpu_buffer_create(&p->g, &p->denoised, 16 * (VkDeviceSize)p->r.accum.width * (VkDeviceSize)p->r.accum.height,
                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
        b[0].buffer = &p->denoised;
        gpu_pipeline_create(&p->g, &p->display_denoised, &pd);
    }
    p->display_width = p->r.accum.width;
    p->display_height = p->r.accum.height;
    p->shown = false;
}

static void record_frame(preview *p, VkImage target, int passes)
{
    VkCommandBuffer cmd = p->cmd;
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                   .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkBufferMemoryBarrier texels = {.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    VkImageMemoryBarrier img = {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    VkBufferImageCopy region = {0};
    GnDisplayPush push = {0};
    bool bgra = p->format.format == VK_FORMAT_B8G8R8A8_UNORM ||
                p->format.format == VK_FORMAT_B8G8R8A8_SRGB;

    GPU_CHECK(vkBeginCommandBuffer(cmd, &bi));
    renderer_record_samples(&p->r, cmd, p->s.mode, (uint32_t)p->spp, (uint32_t)passes);
    push.width = (uint32_t)p->r.accum.width;
    push.height = (uint32_t)p->r.accum.height;
    push.tonemap = (uint32_t)p->tonemap;
    push.flags = bgra ? GN_DISPLAY_BGRA : 0u;
    push.inv_spp = 1.0f / (float)(p->spp + passes > 0 ? p->spp + passes : 1);
    push.scale = exp2f(p->exposure);
    if (denoise_shown(p)) {
        push.inv_spp = 1.0f; /* `denoised` holds means */
        gpu_dispatch(cmd, &p->display_denoised, &push, push.width, push.height, 1);
    } else {
        gpu_dispatch(cmd, &p->display, &push, push.width, push.height, 1);
    }

    /* The texels, written by the kernel, are read by the copy; the image (whose old contents
     * do not matter) becomes a copy destination once the acquire semaphore, waited on at the
     * transfer stage, has signalled. */
    texels.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    texels.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    texels.srcQueueFamilyIndex = texels.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    texels.buffer = p->texels.buffer;
    texels.size = VK_WHOLE_SIZE;
    img.srcAccessMask = 0;
    img.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    img.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    img.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    img.srcQueueFamilyIndex = img.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    img.image = target;
    img.subresourceRange = range;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 1, &texels, 1, &img);
    region.imageSubresource = (VkImageSubresourceLayers){VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = (VkExtent3D){push.width, push.height, 1};
    vkCmdCopyBufferToImage(cmd, p->texels.buffer, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
    img.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    img.dstAccessMask = 0;
    img.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    img.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT,
                         0, 0, NULL, 0, NULL, 1, &img);
    GPU_CHECK(vkEndCommandBuffer(cmd));
}

static void update_title(preview *p)
{
    char t[sizeof p->title];
    snprintf(t, sizeof t, "gonio preview: %s | %dx%d | %d spp | %.2f Mpaths/s | %.1f ms | EV %+.1f %s",
             render_mode_name(p->s.mode), p->r.accum.width, p->r.accum.height, p->spp, p->paths_per_second * 1e-6,
             p->frame_seconds * 1e3, p->exposure, image_tonemap_name(p->tonemap));
    if (p->denoise_unavailable)
        snprintf(t + strlen(t), sizeof t - strlen(t), " | denoiser unavailable");
    else if (p->denoise_view && p->s.mode != GN_MODE_PATH)
        snprintf(t + strlen(t), sizeof t - strlen(t), " | denoise: path mode only");
    else if (denoise_shown(p))
        snprintf(t + strlen(t), sizeof t - strlen(t), " | denoised at %d spp (%.2f s)", p->denoised_spp,
                 p->denoise_seconds);
    else if (p->denoise_view)
        snprintf(t + strlen(t), sizeof t - strlen(t), " | denoising at %d spp", p->denoise_next);
    if (strcmp(t, p->title)) {
        strcpy(p->title, t);
        glfwSetWindowTitle(p->window, t);
    }
}

/* One frame: wait for the last, apply what changed, record passes, display, present.
 * Returns true when a frame was presented. */
static bool frame(preview *p, double *submit_time, int *last_passes)
{
    VkDevice dev = p->g.device;
    VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
    VkPresentInfoKHR pi = {.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    GnFrame fr;
    uint32_t index;
    int fw, fh, passes;
    VkResult res;

    /* Host writes below (save, renderer_begin) need the previous frame finished. */
    GPU_CHECK(vkWaitForFences(dev, 1, &p->fence, VK_TRUE, UINT64_MAX));
    if (*last_passes > 0) {
        double gpu_seconds = util_now() - *submit_time;
        p->paths_per_second = (double)*last_passes * p->r.accum.width * p->r.accum.height / gpu_seconds;
        if (gpu_seconds < 0.5 * PREVIEW_FRAME_SECONDS && p->batch < PREVIEW_MAX_BATCH)
            p->batch *= 2;
        else if (gpu_seconds > 1.5 * PREVIEW_FRAME_SECONDS && p->batch > 1)
            p->batch /= 2;
    }
    /* The paths of the last frame that llvmpipe's loop cap interrupted, finished before
     * anything reads the sums (that frame showed those pixels a little dark). */
    if (*last_passes > 0)
        renderer_finish(&p->r, p->s.mode, (uint32_t)p->spp);
    *last_passes = 0;
    denoise_step(p);
    if (p->save) {
        p->save = false;
        save_accumulated(p);
    }
    glfwGetFramebufferSize(p->window, &fw, &fh);
    if (fw != p->fb_width || fh != p->fb_height || p->stale || !p->swapchain)
        if (!swapchain_create(p))
            return false;
    if (p->restart) {
        p->s.width = (int)p->extent.width;
        p->s.height = (int)p->extent.height;
        /* The start camera frames the scene for the image's aspect, as `gonio render` does. */
        if ((!p->moved && !camera_start(p)) || !renderer_begin(&p->r, &p->s, &fr)) {
            p->failed = true; /* said why */
            return false;
        }
        display_resize(p);
        p->spp = 0;
        p->restart = false;
        p->generation++;
        p->denoised_spp = 0;
        p->denoise_next = PREVIEW_DENOISE_FIRST_SPP;
    }

    res = vkAcquireNextImageKHR(dev, p->swapchain, UINT64_MAX, p->acquired, VK_NULL_HANDLE, &index);
    if (res == VK_ERROR_OUT_OF_DATE_KHR) {
        p->stale = true;
        return false;
    }
    if (res != VK_SUBOPTIMAL_KHR)
        GPU_CHECK(res);
    passes = p->batch;
    if (p->max_spp > 0 && passes > p->max_spp - p->spp)
        passes = p->max_spp - p->spp;
    record_frame(p, p->images[index], passes);

    GPU_CHECK(vkResetFences(dev, 1, &p->fence));
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &p->acquired;
    si.pWaitDstStageMask = &wait_stage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &p->cmd;
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &p->presentable[index];
    *submit_time = util_now();
    GPU_CHECK(vkQueueSubmit(p->g.queue, 1, &si, p->fence));
    *last_passes = passes;
    p->spp += passes;
    p->shown = true;
    p->redraw = false;

    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &p->presentable[index];
    pi.swapchainCount = 1;
    pi.pSwapchains = &p->swapchain;
    pi.pImageIndices = &index;
    res = vkQueuePresentKHR(p->g.queue, &pi);
    if (res == VK_ERROR_OUT_OF_DATE_KHR || res == VK_SUBOPTIMAL_KHR)
        p->stale = true;
    else
        GPU_CHECK(res);
    return true;
}

/* ---- the command ------------------------------------------------------------------------ */

/* Converged and nothing to show anew: frames then only repaint, at a low rate. */
static bool idle(const preview *p)
{
    return p->max_spp > 0 && p->spp >= p->max_spp && !p->restart && !p->save && !p->redraw;
}

static bool setup(preview *p, int device, bool validate, int width, int height)
{
    const char *env = getenv("GONIO_VALIDATE");
    uint32_t num_ext = 0;
    const char *const *ext;
    gpu_desc gd = {.device_index = device, .swapchain = true};
    VkSemaphoreCreateInfo semi = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkFenceCreateInfo fci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO,
                             .flags = VK_FENCE_CREATE_SIGNALED_BIT};
    VkCommandBufferAllocateInfo cai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    VkResult res;

    if (!glfwVulkanSupported()) {
        util_error("GLFW finds no Vulkan loader; use `gonio render` to render to files");
        return false;
    }
    ext = glfwGetRequiredInstanceExtensions(&num_ext);
    if (!ext) {
        util_error("this display offers no Vulkan surface; use `gonio render` to render to files");
        return false;
    }
    gd.instance_extensions = ext;
    gd.num_instance_extensions = num_ext;
    gd.validate = validate || (env && strcmp(env, "1") == 0);
    if (!gpu_create(&p->g, &gd))
        return false;
    if (!glfwGetPhysicalDevicePresentationSupport(p->g.instance, p->g.physical, p->g.queue_family)) {
        util_error("%s cannot present to this display; try another --device (see gonio devices) "
                   "or use `gonio render`", p->g.props.deviceName);
        return false;
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    p->window = glfwCreateWindow(width, height, "gonio preview", NULL, NULL);
    if (!p->window) {
        util_error("cannot open a window; use `gonio render` to render to files");
        return false;
    }
    res = glfwCreateWindowSurface(p->g.instance, p->window, NULL, &p->surface);
    if (res != VK_SUCCESS) {
        util_error("cannot create a Vulkan surface for the window (%s)", gpu_result_name(res));
        return false;
    }
    if (!choose_surface(p))
        return false;
    GPU_CHECK(vkCreateSemaphore(p->g.device, &semi, NULL, &p->acquired));
    GPU_CHECK(vkCreateFence(p->g.device, &fci, NULL, &p->fence));
    cai.commandPool = p->g.pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    GPU_CHECK(vkAllocateCommandBuffers(p->g.device, &cai, &p->cmd));
    renderer_create(&p->r, &p->g, &p->sc);
    glfwSetWindowUserPointer(p->window, p);
    glfwSetKeyCallback(p->window, on_key);
    glfwSetCursorPosCallback(p->window, on_cursor);
    glfwSetScrollCallback(p->window, on_scroll);
    glfwGetCursorPos(p->window, &p->mouse_x, &p->mouse_y);
    p->restart = true;
    p->s.width = width;
    p->s.height = height;
    return camera_start(p);
}

static bool teardown(preview *p)
{
    VkDevice dev = p->g.device;
    if (dev) {
        vkDeviceWaitIdle(dev);
        destroy_presentable(p);
        if (p->swapchain)
            vkDestroySwapchainKHR(dev, p->swapchain, NULL);
        if (p->acquired)
            vkDestroySemaphore(dev, p->acquired, NULL);
        if (p->fence)
            vkDestroyFence(dev, p->fence, NULL);
        if (p->cmd)
            vkFreeCommandBuffers(dev, p->g.pool, 1, &p->cmd);
        gpu_pipeline_destroy(&p->g, &p->display);
        gpu_buffer_destroy(&p->g, &p->texels);
        gpu_pipeline_destroy(&p->g, &p->display_denoised);
        gpu_buffer_destroy(&p->g, &p->denoised);
        renderer_destroy(&p->r);
    }
    if (p->surface)
        vkDestroySurfaceKHR(p->g.instance, p->surface, NULL);
    if (p->window)
        glfwDestroyWindow(p->window);
    preview_denoiser_stop(&p->denoiser);
    denoise_shutdown();
    return cli_gpu_finish(&p->g);
}

/* The scene with its light and its first view, and the window's size. */
static bool load_view(preview *p, const char *scene_path, int scene_index, camera_option *cam,
                      const render_light_request *env, bool size_given, int *width, int *height,
                      scene_camera *start_view, render_lighting *light)
{
    if (!scene_load_scene(&p->sc, scene_path, scene_index))
        return false;
    if (!render_light_begin(env, &p->sc, false, &p->s, light) ||
        !camera_resolve(cam, &p->sc, size_given ? (float)*width / (float)*height : 1.0f, start_view))
        return false;
    /* The shared rule (src/scene/camera.h): the file's cameras by index, so that C steps on. */
    p->s.camera = cam->kind == CAMERA_INDEX ? cam->index : cam->kind == CAMERA_AUTO && p->sc.num_cameras ? 0 : -1;
    if (cam->kind == CAMERA_LOOK_AT || cam->fov > 0) /* --fov: that view, as render has it */
        p->start_view = p->s.view = start_view;
    if (!size_given && cam->width > 0) { /* --camera FILE.exr: that render's size */
        *width = cam->width;
        *height = cam->height;
    }
    if (!size_given && p->s.camera >= 0 && start_view->aspect > 0)
        *height = (int)fmaxf(1.0f, 640.0f / start_view->aspect + 0.5f);
    p->start_camera = p->s.camera;
    return true;
}

/* --denoise: the library and the denoiser's thread, before the window (a clear error and
 * exit 1 without them), and the guides rendered. */
static bool start_denoiser(preview *p)
{
    if (!denoise_load() || !preview_denoiser_start(&p->denoiser))
        return false;
    p->denoise_view = true;
    p->s.aov |= RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL;
    return true;
}

/* The window's loop until it is closed, Q, or max_frames frames (0: no limit); then what
 * P asked to save and the screenshot. False when a frame failed or a file could not be
 * written. */
static bool run_window(preview *p, const char *scene_path, int max_frames, const char *screenshot)
{
    double submit_time = 0, last_frame = util_now();
    int frames = 0, last_passes = 0;
    bool ok = true;
    util_info("preview: %s on %s; press H in the window for the keys", scene_path, p->g.props.deviceName);
    while (!glfwWindowShouldClose(p->window) && !p->quit_key) {
        if (idle(p))
            glfwWaitEventsTimeout(PREVIEW_IDLE_SECONDS);
        else
            glfwPollEvents();
        double now = util_now();
        if (idle(p) && now - last_frame < PREVIEW_IDLE_SECONDS)
            continue; /* woken early by an event that changed nothing */
        fly(p, (float)fmin(now - last_frame, 0.1));
        if (!frame(p, &submit_time, &last_passes)) {
            if (p->failed) {
                ok = false;
                break;
            }
            glfwWaitEventsTimeout(PREVIEW_IDLE_SECONDS); /* minimised */
            continue;
        }
        p->frame_seconds = now - last_frame;
        last_frame = now;
        update_title(p);
        if (max_frames && ++frames >= max_frames)
            break;
    }
    vkDeviceWaitIdle(p->g.device);
    if (p->save)
        ok = save_accumulated(p) && ok;
    if (screenshot)
        ok = save_screenshot(p, screenshot) && ok;
    util_info("preview: %d frame(s), %s, %d spp, %dx%d", frames, render_mode_name(p->s.mode), p->spp,
              p->r.accum.width, p->r.accum.height);
    return ok;
}

int cmd_preview(int argc, char **argv)
{
    static preview pv; /* large, and the GLFW callbacks reach it through the window */
    preview *p = &pv;
    const char *scene_path = NULL, *screenshot = NULL;
    bool validate = false, size_given = false, ok = true;
    int device = -1, width, height, size[2] = {640, 480}, max_frames = 0;
    camera_option cam = {0};
    env_option env = {0};
    render_lighting light = {0};
    scene_camera start_view;

    memset(p, 0, sizeof *p);
    p->s = (render_settings){.mode = GN_MODE_PATH, .camera = -1};
    p->prefix = "gonio-preview";
    p->batch = 1;
    bool no_shadows = false, quiet = false, outside = false, denoise = false;
    int scene_index = -1;
    const cli_option options[] = {
        CLI_OPT_MODE(&p->s.mode),
        CLI_OPT_SPP(&p->max_spp, "stop accumulating at N samples per pixel (default: never)"),
        CLI_OPT_SIZE(size, "initial window size (default 640 wide, the camera's aspect)"),
        CAMERA_OPTIONS(&cam),
        CLI_OPT_SCENE(&scene_index, "show the file's glTF scene N (default: its default scene)"),
        CLI_OPT_VARIANT("the glTF KHR_materials_variants variant NAME's materials"),
        CLI_OPT_ALLOW_OUTSIDE_FILES(&outside),
        CLI_OPT_SEED(&p->s.seed, "random seed (default 0)"),
        CLI_OPT_SAMPLER(&p->s.sampler),
        CLI_OPT_MAX_DEPTH(&p->s.max_depth, "path tracer: maximum path length (default 0: roulette only)"),
        ENV_OPTIONS(&env),
        CLI_OPT_NO_SHADOWS(&no_shadows),
        CLI_OPT_EXPOSURE(&p->exposure, "display scale 2^E (default 0)"),
        CLI_OPT_TONEMAP(&p->tonemap, "clamp (default), reinhard, aces"),
        CLI_OPT_DENOISE(&denoise, "start with the denoised view (key N; OIDN, as render --denoise)"),
        {"--prefix", "P", "P writes P-NNN.exr and P-NNN.png (default gonio-preview)", CLI_STRING, CLI_AS(const char *, &p->prefix),
         0, 0, NULL, NULL, NULL},
        {"--frames", "N", "quit after N frames (scripts, tests)", CLI_INT, CLI_AS(int, &max_frames), 1, 1 << 30,
         "an integer >= 1", NULL, NULL},
        {"--screenshot", "FILE", "on quitting, write what the window shows as PNG", CLI_STRING, CLI_AS(const char *, &screenshot), 0,
         0, NULL, NULL, "*.png"},
        CLI_OPT_DEVICE(&device),
        CLI_OPT_VALIDATE(&validate),
        CLI_OPT_QUIET(&quiet, "no informational messages"),
    };
    const cli_command command = {.name = "preview", .synopsis = "SCENE.gltf|.glb [options]",
                                 .intro = "Opens a window and shows the render converging; press H in it for the keys.\n",
                                 CLI_OPTIONS(options), .epilog = keys_help(), .min_args = 1, .max_args = 1,
                                 .missing = "no scene given", .complete_args = "*.gltf *.glb"};
    cli_args args;
    int rc = cli_parse(&command, argc, argv, &args);
    if (rc >= 0)
        return rc;
    scene_path = args.arg[0];
    width = size[0];
    height = size[1];
    size_given = cli_given(&command, &args, "--size");
    p->s.no_shadows = no_shadows;
    util_set_quiet(quiet);
    scene_allow_outside_files(outside);
    if (screenshot && image_format_of(screenshot) != IMAGE_FORMAT_PNG)
        return cli_usage_error("preview", "--screenshot '%s': expected a .png name", screenshot);
    if (screenshot && !util_check_output(screenshot))
        return 1;

    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) {
        util_error("no display to open a window on: `gonio preview` needs one (X11). Render "
                   "to files with `gonio render`, or run under a virtual display: "
                   "xvfb-run gonio preview %s", scene_path);
        return 1;
    }
    if (!load_view(p, scene_path, scene_index, &cam, &env, size_given, &width, &height, &start_view, &light) ||
        (denoise && !start_denoiser(p))) {
        ok = false;
    } else if (setup(p, device, validate, width, height)) {
        bool had_studio = light.studio;
        ok = render_light_finish(&env, &p->sc, &p->r, &p->s, false, &light);
        if (light.studio != had_studio || light.headlight)
            p->restart = true;
        ok = ok && run_window(p, scene_path, max_frames, screenshot);
        ok = teardown(p) && ok;
    } else {
        teardown(p);
        ok = false;
    }
    glfwTerminate();
    scene_destroy(&p->sc);
    p->s.env_map = NULL;
    render_lighting_destroy(&light);
    return ok ? 0 : 1;
}
