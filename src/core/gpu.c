/* gpu.c: Vulkan compute: instance/device selection, buffers, pipelines, submission. */
#define _GNU_SOURCE /* dl_iterate_phdr, RTLD_NODELETE (sanitizer builds) */
#include "gpu.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spirv_specialise.h"
#include "util.h"

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>

/* The Vulkan loader unloads the driver at vkDestroyInstance; LeakSanitizer reports at exit
 * and can then no longer name the driver's frames, so tests/lsan.supp cannot suppress the
 * allocations Mesa and LLVM keep. Sanitizer builds pin every library loaded so far. */
static int pin_library(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    (void)data;
    if (info->dlpi_name && info->dlpi_name[0])
        dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    return 0;
}

static void pin_loaded_libraries(void) { dl_iterate_phdr(pin_library, NULL); }
#else
static void pin_loaded_libraries(void) {}
#endif

static int validation_messages;

const char *gpu_result_name(VkResult r)
{
    switch (r) {
#define R(x) case x: return #x;
        R(VK_SUCCESS) R(VK_NOT_READY) R(VK_TIMEOUT) R(VK_EVENT_SET) R(VK_EVENT_RESET)
        R(VK_INCOMPLETE) R(VK_ERROR_OUT_OF_HOST_MEMORY) R(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        R(VK_ERROR_INITIALIZATION_FAILED) R(VK_ERROR_DEVICE_LOST) R(VK_ERROR_MEMORY_MAP_FAILED)
        R(VK_ERROR_LAYER_NOT_PRESENT) R(VK_ERROR_EXTENSION_NOT_PRESENT)
        R(VK_ERROR_FEATURE_NOT_PRESENT) R(VK_ERROR_INCOMPATIBLE_DRIVER)
        R(VK_ERROR_TOO_MANY_OBJECTS) R(VK_ERROR_FORMAT_NOT_SUPPORTED)
        R(VK_ERROR_FRAGMENTED_POOL) R(VK_ERROR_UNKNOWN) R(VK_ERROR_OUT_OF_POOL_MEMORY)
        R(VK_ERROR_SURFACE_LOST_KHR) R(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR) R(VK_SUBOPTIMAL_KHR)
        R(VK_ERROR_OUT_OF_DATE_KHR) R(VK_ERROR_VALIDATION_FAILED_EXT)
#undef R
    default: return "VK_RESULT_UNKNOWN";
    }
}

void gpu_check(VkResult r, const char *call, const char *file, int line)
{
    if (r == VK_SUCCESS)
        return;
    fprintf(stderr, "gonio: Vulkan error: %s returned %s (%d) at %s:%d\n", call,
            gpu_result_name(r), (int)r, file, line);
    exit(1);
}

int gpu_validation_message_count(void) { return validation_messages; }

static VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)types;
    (void)user;
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        validation_messages++;
        fprintf(stderr, "gonio: validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

const char *gpu_device_type_name(VkPhysicalDeviceType t)
{
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
    }
}

/* Lower is preferred: a real GPU first, lavapipe last. */
static int type_rank(VkPhysicalDeviceType t)
{
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
    }
}

static bool has_layer(const char *name)
{
    uint32_t n = 0;
    VkLayerProperties *props;
    bool found = false;
    vkEnumerateInstanceLayerProperties(&n, NULL);
    props = util_calloc(n, sizeof *props);
    vkEnumerateInstanceLayerProperties(&n, props);
    for (uint32_t i = 0; i < n; i++)
        found |= strcmp(props[i].layerName, name) == 0;
    free(props);
    return found;
}

static bool create_instance(gpu *g, const gpu_desc *desc)
{
    const char *exts[16];
    uint32_t n = 0;
    const char *layer = "VK_LAYER_KHRONOS_validation";
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO};
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    VkDebugUtilsMessengerCreateInfoEXT dbg = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    VkResult r;

    for (uint32_t i = 0; i < desc->num_instance_extensions && n < 15; i++)
        exts[n++] = desc->instance_extensions[i];
    if (desc->validate) {
        if (!has_layer(layer)) {
            util_error("--validate: %s is not installed (Debian: apt-get install "
                       "vulkan-validationlayers)", layer);
            return false;
        }
        exts[n++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
        ci.enabledLayerCount = 1;
        ci.ppEnabledLayerNames = &layer;
        dbg.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        dbg.pfnUserCallback = debug_callback;
        ci.pNext = &dbg; /* also reports problems of vkCreateInstance itself */
    }
    app.pApplicationName = "gonio";
    app.apiVersion = VK_API_VERSION_1_1;
    ci.pApplicationInfo = &app;
    ci.enabledExtensionCount = n;
    ci.ppEnabledExtensionNames = exts;
    r = vkCreateInstance(&ci, NULL, &g->instance);
    if (r != VK_SUCCESS) {
        util_error("cannot create a Vulkan instance (%s): is a Vulkan driver installed? "
                   "(Debian: apt-get install mesa-vulkan-drivers)", gpu_result_name(r));
        return false;
    }
    if (desc->validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create = (PFN_vkCreateDebugUtilsMessengerEXT)
            vkGetInstanceProcAddr(g->instance, "vkCreateDebugUtilsMessengerEXT");
        if (create)
            GPU_CHECK(create(g->instance, &dbg, NULL, &g->messenger));
    }
    return true;
}

static VkPhysicalDevice *list_devices(VkInstance inst, uint32_t *count)
{
    VkPhysicalDevice *devs;
    GPU_CHECK(vkEnumeratePhysicalDevices(inst, count, NULL));
    devs = util_calloc(*count, sizeof *devs);
    GPU_CHECK(vkEnumeratePhysicalDevices(inst, count, devs));
    return devs;
}

static int compute_queue_family(VkPhysicalDevice dev)
{
    uint32_t n = 0;
    VkQueueFamilyProperties *q;
    int best = -1;
    vkGetPhysicalDeviceQueueFamilyProperties(dev, &n, NULL);
    q = util_calloc(n, sizeof *q);
    vkGetPhysicalDeviceQueueFamilyProperties(dev, &n, q);
    /* A family with graphics too is preferred: the preview presents from the same queue. */
    for (uint32_t i = 0; i < n; i++)
        if ((q[i].queueFlags & VK_QUEUE_COMPUTE_BIT) &&
            (best < 0 || (q[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)))
            best = (int)i;
    free(q);
    return best;
}

bool gpu_create(gpu *g, const gpu_desc *desc)
{
    VkPhysicalDevice *devs;
    uint32_t count = 0;
    int chosen = -1, family;
    float priority = 1.0f;
    VkDeviceQueueCreateInfo qci = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    VkDeviceCreateInfo dci = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    VkCommandPoolCreateInfo pci = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    const char *swapchain_ext = VK_KHR_SWAPCHAIN_EXTENSION_NAME;

    memset(g, 0, sizeof *g);
    g->validate = desc->validate;
    if (!create_instance(g, desc))
        return false;
    devs = list_devices(g->instance, &count);
    /* Here, not after the checks below: their error paths destroy the instance too. */
    pin_loaded_libraries();
    if (count == 0) {
        util_error("no Vulkan device found (Debian: apt-get install mesa-vulkan-drivers)");
        free(devs);
        gpu_destroy(g);
        return false;
    }
    if (desc->device_index >= 0) {
        if ((uint32_t)desc->device_index >= count) {
            util_error("--device %d: only %u device(s) (see `gonio devices`)",
                       desc->device_index, count);
            free(devs);
            gpu_destroy(g);
            return false;
        }
        chosen = desc->device_index;
    } else {
        int best_rank = 99;
        for (uint32_t i = 0; i < count; i++) {
            VkPhysicalDeviceProperties p;
            vkGetPhysicalDeviceProperties(devs[i], &p);
            if (compute_queue_family(devs[i]) >= 0 && type_rank(p.deviceType) < best_rank) {
                best_rank = type_rank(p.deviceType);
                chosen = (int)i;
            }
        }
    }
    family = chosen >= 0 ? compute_queue_family(devs[chosen]) : -1;
    if (family < 0) {
        util_error("no Vulkan device with a compute queue");
        free(devs);
        gpu_destroy(g);
        return false;
    }
    g->physical = devs[chosen];
    free(devs);
    g->queue_family = (uint32_t)family;
    {
        VkPhysicalDeviceMaintenance3Properties m3 = {
            .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
        VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                          .pNext = &m3};
        vkGetPhysicalDeviceProperties2(g->physical, &p2);
        g->props = p2.properties;
        g->max_allocation = m3.maxMemoryAllocationSize;
    }
    vkGetPhysicalDeviceMemoryProperties(g->physical, &g->memory);
    g->unified_memory = true;
    for (uint32_t i = 0; i < g->memory.memoryTypeCount; i++) {
        VkMemoryPropertyFlags f = g->memory.memoryTypes[i].propertyFlags;
        if ((f & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) && !(f & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT))
            g->unified_memory = false;
    }

    qci.queueFamilyIndex = g->queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    if (desc->swapchain) {
        dci.enabledExtensionCount = 1;
        dci.ppEnabledExtensionNames = &swapchain_ext;
    }
    GPU_CHECK(vkCreateDevice(g->physical, &dci, NULL, &g->device));
    vkGetDeviceQueue(g->device, g->queue_family, 0, &g->queue);
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = g->queue_family;
    GPU_CHECK(vkCreateCommandPool(g->device, &pci, NULL, &g->pool));
    return true;
}

static void gpu_kernels_destroy(gpu *g);

void gpu_destroy(gpu *g)
{
    if (g->device) {
        vkDeviceWaitIdle(g->device);
        gpu_kernels_destroy(g);
        if (g->pool)
            vkDestroyCommandPool(g->device, g->pool, NULL);
        vkDestroyDevice(g->device, NULL);
    }
    if (g->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)
            vkGetInstanceProcAddr(g->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy)
            destroy(g->instance, g->messenger, NULL);
    }
    if (g->instance)
        vkDestroyInstance(g->instance, NULL);
    memset(g, 0, sizeof *g);
}

static bool has_device_extension(const VkExtensionProperties *e, uint32_t n, const char *name)
{
    for (uint32_t i = 0; i < n; i++)
        if (strcmp(e[i].extensionName, name) == 0)
            return true;
    return false;
}

const char *gpu_ray_query_missing(VkPhysicalDevice dev)
{
    /* VK_KHR_acceleration_structure requires VK_KHR_deferred_host_operations. */
    static const char *const exts[] = {VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                       VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                       VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    static char missing[160];
    VkPhysicalDeviceRayQueryFeaturesKHR rq = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR as = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, .pNext = &rq};
    VkPhysicalDeviceFeatures2 f2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &as};
    VkExtensionProperties *e;
    uint32_t n = 0;

    GPU_CHECK(vkEnumerateDeviceExtensionProperties(dev, NULL, &n, NULL));
    e = util_calloc(n ? n : 1, sizeof *e);
    GPU_CHECK(vkEnumerateDeviceExtensionProperties(dev, NULL, &n, e));
    missing[0] = 0;
    for (size_t i = 0; i < sizeof exts / sizeof *exts; i++)
        if (!has_device_extension(e, n, exts[i]))
            snprintf(missing + strlen(missing), sizeof missing - strlen(missing), "%s%s",
                     missing[0] ? ", " : "", exts[i]);
    free(e);
    if (missing[0])
        return missing;
    /* The features' structures are chained only once the extensions are known to be there. */
    vkGetPhysicalDeviceFeatures2(dev, &f2);
    if (!as.accelerationStructure)
        return "the accelerationStructure feature";
    if (!rq.rayQuery)
        return "the rayQuery feature";
    return NULL;
}

bool gpu_print_devices(void)
{
    gpu g = {0};
    gpu_desc desc = {.device_index = -1};
    VkPhysicalDevice *devs;
    uint32_t count = 0;
    bool any_missing = false;
    if (!create_instance(&g, &desc))
        return false;
    devs = list_devices(g.instance, &count);
    pin_loaded_libraries(); /* the drivers just loaded, as gpu_create does */
    /* The driver, the longest and most variable field, comes last. */
    printf("%-5s %-40s %-10s %-9s %-11s %s\n", "index", "name", "type", "api", "ray queries",
           "driver");
    for (uint32_t i = 0; i < count; i++) {
        VkPhysicalDeviceDriverProperties drv = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
        VkPhysicalDeviceProperties2 p2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &drv};
        char api[32];
        uint32_t v;
        bool ray_query;
        vkGetPhysicalDeviceProperties2(devs[i], &p2);
        v = p2.properties.apiVersion;
        snprintf(api, sizeof api, "%u.%u.%u", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v),
                 VK_API_VERSION_PATCH(v));
        ray_query = gpu_ray_query_missing(devs[i]) == NULL;
        any_missing |= !ray_query;
        printf("%-5u %-40s %-10s %-9s %-11s %s %s\n", i, p2.properties.deviceName,
               gpu_device_type_name(p2.properties.deviceType), api, ray_query ? "yes" : "no",
               drv.driverName, drv.driverInfo);
    }
    /* What a device without ray queries lacks, under the table. */
    if (any_missing)
        printf("\n");
    for (uint32_t i = 0; i < count; i++) {
        const char *missing = gpu_ray_query_missing(devs[i]);
        if (missing)
            printf("device %u: no ray queries: it lacks %s\n", i, missing);
    }
    free(devs);
    gpu_destroy(&g);
    return true;
}

/* ---- limits ------------------------------------------------------------------------ */

/* A positive integer from the environment, or `none` when unset or not a number. */
static uint64_t env_limit(const char *name, uint64_t none)
{
    const char *v = getenv(name);
    char *end;
    unsigned long long x;
    if (!v || !*v)
        return none;
    x = strtoull(v, &end, 10);
    return *end || x == 0 ? none : (uint64_t)x;
}

VkDeviceSize gpu_storage_limit(const gpu *g, const char **name)
{
    VkDeviceSize limit = g->props.limits.maxStorageBufferRange, forced;
    const char *n = "maxStorageBufferRange";
    if (g->max_allocation && g->max_allocation < limit) {
        limit = g->max_allocation;
        n = "maxMemoryAllocationSize";
    }
    forced = env_limit("GONIO_MAX_BUFFER_BYTES", UINT64_MAX);
    if (forced < limit) {
        limit = forced;
        n = "GONIO_MAX_BUFFER_BYTES";
    }
    if (name)
        *name = n;
    return limit;
}

VkDeviceSize gpu_host_heap(const gpu *g)
{
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                       VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkDeviceSize best = 0;
    for (uint32_t i = 0; i < g->memory.memoryTypeCount; i++) {
        VkDeviceSize size = g->memory.memoryHeaps[g->memory.memoryTypes[i].heapIndex].size;
        if ((g->memory.memoryTypes[i].propertyFlags & host) == host && size > best)
            best = size;
    }
    return best;
}

uint32_t gpu_max_texels(const gpu *g, const char **name)
{
    uint64_t n = g->props.limits.maxTexelBufferElements;
    uint64_t forced = env_limit("GONIO_MAX_TEXELS", n);
    if (name)
        *name = forced < n ? "GONIO_MAX_TEXELS" : "maxTexelBufferElements";
    return (uint32_t)(forced < n ? forced : n);
}

uint32_t gpu_max_groups(const gpu *g, int axis)
{
    uint64_t n = g->props.limits.maxComputeWorkGroupCount[axis];
    uint64_t forced = env_limit("GONIO_MAX_WORKGROUPS", n);
    return (uint32_t)(forced < n ? forced : n);
}

/* ---- memory and buffers ------------------------------------------------------------- */

static uint32_t memory_type(const gpu *g, uint32_t bits, VkMemoryPropertyFlags want,
                            VkMemoryPropertyFlags fallback)
{
    for (int pass = 0; pass < 2; pass++) {
        VkMemoryPropertyFlags f = pass ? fallback : want;
        for (uint32_t i = 0; i < g->memory.memoryTypeCount; i++)
            if ((bits & (1u << i)) && (g->memory.memoryTypes[i].propertyFlags & f) == f)
                return i;
    }
    fprintf(stderr, "gonio: Vulkan error: no suitable memory type\n");
    exit(1);
}

void gpu_buffer_create(gpu *g, gpu_buffer *b, VkDeviceSize size, VkBufferUsageFlags usage,
                       gpu_memory where)
{
    VkBufferCreateInfo bci = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    VkMemoryAllocateInfo mai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    VkMemoryRequirements req;
    VkMemoryPropertyFlags want, fallback;
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                       VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

    memset(b, 0, sizeof *b);
    b->size = size ? size : 16;
    bci.size = b->size;
    bci.usage = usage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    GPU_CHECK(vkCreateBuffer(g->device, &bci, NULL, &b->buffer));
    vkGetBufferMemoryRequirements(g->device, b->buffer, &req);
    if (where == GPU_MEMORY_HOST) {
        want = host | VK_MEMORY_PROPERTY_HOST_CACHED_BIT; /* fast readback */
        fallback = host;
    } else {
        want = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
        fallback = 0;
    }
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(g, req.memoryTypeBits, want, fallback);
    GPU_CHECK(vkAllocateMemory(g->device, &mai, NULL, &b->memory));
    GPU_CHECK(vkBindBufferMemory(g->device, b->buffer, b->memory, 0));
    /* Mapped only when coherent, so plain memcpy is enough (lavapipe: all memory). */
    if ((g->memory.memoryTypes[mai.memoryTypeIndex].propertyFlags & host) == host)
        GPU_CHECK(vkMapMemory(g->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->mapped));
}

void gpu_buffer_create_texels(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size)
{
    gpu_buffer_create_texels_as(g, b, data, size, VK_FORMAT_R32G32B32A32_UINT);
}

void gpu_buffer_create_texels_as(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size,
                                 VkFormat format)
{
    VkBufferViewCreateInfo vci = {.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    gpu_buffer_create(g, b, size, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT, GPU_MEMORY_DEVICE);
    if (data)
        gpu_buffer_upload(g, b, data, size, 0);
    else
        gpu_buffer_fill_zero(g, b);
    vci.buffer = b->buffer;
    vci.format = format;
    vci.range = b->size;
    GPU_CHECK(vkCreateBufferView(g->device, &vci, NULL, &b->view));
}

void gpu_buffer_destroy(gpu *g, gpu_buffer *b)
{
    if (b->view)
        vkDestroyBufferView(g->device, b->view, NULL);
    if (b->buffer)
        vkDestroyBuffer(g->device, b->buffer, NULL);
    if (b->memory)
        vkFreeMemory(g->device, b->memory, NULL); /* unmaps implicitly */
    memset(b, 0, sizeof *b);
}

static void staged_copy(gpu *g, const gpu_buffer *dst, const gpu_buffer *src,
                        VkDeviceSize size, VkDeviceSize dst_off, VkDeviceSize src_off)
{
    VkCommandBuffer cmd = gpu_begin(g);
    VkBufferCopy region = {src_off, dst_off, size};
    vkCmdCopyBuffer(cmd, src->buffer, dst->buffer, 1, &region);
    gpu_submit_wait(g, cmd);
}

void gpu_buffer_upload(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size,
                       VkDeviceSize offset)
{
    gpu_buffer staging;
    if (!size)
        return;
    if (b->mapped) {
        memcpy((char *)b->mapped + offset, data, size);
        return;
    }
    gpu_buffer_create(g, &staging, size, 0, GPU_MEMORY_HOST);
    memcpy(staging.mapped, data, size);
    staged_copy(g, b, &staging, size, offset, 0);
    gpu_buffer_destroy(g, &staging);
}

void gpu_buffer_download(gpu *g, const gpu_buffer *b, void *data, VkDeviceSize size,
                         VkDeviceSize offset)
{
    gpu_buffer staging;
    if (!size)
        return;
    if (b->mapped) {
        memcpy(data, (const char *)b->mapped + offset, size);
        return;
    }
    gpu_buffer_create(g, &staging, size, 0, GPU_MEMORY_HOST);
    staged_copy(g, &staging, b, size, 0, offset);
    memcpy(data, staging.mapped, size);
    gpu_buffer_destroy(g, &staging);
}

void gpu_buffer_fill_zero(gpu *g, gpu_buffer *b)
{
    VkCommandBuffer cmd;
    if (b->mapped) {
        memset(b->mapped, 0, b->size);
        return;
    }
    cmd = gpu_begin(g);
    vkCmdFillBuffer(cmd, b->buffer, 0, VK_WHOLE_SIZE, 0);
    gpu_submit_wait(g, cmd);
}

void gpu_buffer_create_storage(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size)
{
    gpu_buffer_create(g, b, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_DEVICE);
    if (data)
        gpu_buffer_upload(g, b, data, size, 0);
    else
        gpu_buffer_fill_zero(g, b);
}

/* ---- pipelines ---------------------------------------------------------------------- */

/* The device's kernels: each (SPIR-V, specialisation, bindings, push constants) is compiled
 * once and shared by every pipeline that asks for it, while each gpu_pipeline has a
 * descriptor set of its own. Compiling a kernel is what a render's setup costs most on
 * lavapipe (about a second for the path kernel, more when LLVM compiles it anew): renderers
 * made again for the same scene kind (an animation's frames, a probe, a test's scenes) find
 * it here. Kernels no pipeline uses stay until GPU_KERNELS_KEPT are kept, then the least
 * recently used goes. */
#define GPU_KERNELS_KEPT 64
#define GPU_SPEC_BYTES 64
#define GPU_SPEC_ENTRIES 16
struct gpu_kernel {
    const uint32_t *code;
    size_t code_size;
    bool on_host; /* its constants folded in by the host (spirv_specialise), not the driver */
    uint32_t push_size, num_bindings;
    VkDescriptorSetLayoutBinding bindings[32];
    uint32_t num_entries, spec_size;
    VkSpecializationMapEntry entries[GPU_SPEC_ENTRIES];
    unsigned char spec[GPU_SPEC_BYTES];
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    uint32_t users;
    uint64_t used; /* the cache's clock at its last use */
};
struct gpu_kernels {
    gpu_kernel **items;
    uint32_t count, cap;
    uint64_t clock;
};

static void kernel_destroy(gpu *g, gpu_kernel *k)
{
    vkDestroyPipeline(g->device, k->pipeline, NULL);
    vkDestroyPipelineLayout(g->device, k->layout, NULL);
    vkDestroyDescriptorSetLayout(g->device, k->set_layout, NULL);
    free(k);
}

static void gpu_kernels_destroy(gpu *g)
{
    if (!g->kernels)
        return;
    for (uint32_t i = 0; i < g->kernels->count; i++)
        kernel_destroy(g, g->kernels->items[i]);
    free(g->kernels->items);
    free(g->kernels);
    g->kernels = NULL;
}

uint32_t gpu_kernel_count(const gpu *g) { return g->kernels ? g->kernels->count : 0; }

/* The key of desc's kernel in k (all but the Vulkan objects). */
static void kernel_key(gpu_kernel *k, const gpu_pipeline_desc *desc)
{
    const VkSpecializationInfo *si = desc->specialization;
    memset(k, 0, sizeof *k);
    k->code = desc->code;
    k->code_size = desc->code_size;
    /* GONIO_DRIVER_SPECIALISE: the driver specialises the module as built, for checking that
     * folding on the host changes nothing (tests/regress/path.sh) and for ruling it out when
     * chasing a bug; another kernel, so a batch line that sets it gets its own. */
    k->on_host = !getenv("GONIO_DRIVER_SPECIALISE");
    k->push_size = desc->push_size;
    k->num_bindings = desc->num_bindings;
    for (uint32_t i = 0; i < desc->num_bindings; i++)
        k->bindings[i] = (VkDescriptorSetLayoutBinding){desc->bindings[i].binding, desc->bindings[i].type, 1,
                                                        VK_SHADER_STAGE_COMPUTE_BIT, NULL};
    if (si) {
        assert(si->mapEntryCount <= GPU_SPEC_ENTRIES && si->dataSize <= GPU_SPEC_BYTES);
        k->num_entries = si->mapEntryCount;
        k->spec_size = (uint32_t)si->dataSize;
        memcpy(k->entries, si->pMapEntries, sizeof *si->pMapEntries * si->mapEntryCount);
        memcpy(k->spec, si->pData, si->dataSize);
    }
}

static bool kernel_same(const gpu_kernel *a, const gpu_kernel *b)
{
    return a->code == b->code && a->code_size == b->code_size && a->on_host == b->on_host &&
           a->push_size == b->push_size &&
           a->num_bindings == b->num_bindings && a->num_entries == b->num_entries && a->spec_size == b->spec_size &&
           !memcmp(a->bindings, b->bindings, sizeof *a->bindings * a->num_bindings) &&
           !memcmp(a->entries, b->entries, sizeof *a->entries * a->num_entries) &&
           !memcmp(a->spec, b->spec, a->spec_size);
}

/* desc's kernel: the one kept, or a new one compiled (and an unused one let go if too many
 * are kept). */
static gpu_kernel *kernel_get(gpu *g, const gpu_pipeline_desc *desc)
{
    gpu_kernel key, *k;
    struct gpu_kernels *c;
    kernel_key(&key, desc);
    if (!g->kernels)
        g->kernels = util_calloc(1, sizeof *g->kernels);
    c = g->kernels;
    c->clock++;
    for (uint32_t i = 0; i < c->count; i++)
        if (kernel_same(c->items[i], &key)) {
            c->items[i]->used = c->clock;
            return c->items[i];
        }
    if (c->count >= GPU_KERNELS_KEPT) { /* let the least recently used idle kernel go */
        uint32_t oldest = c->count;
        for (uint32_t i = 0; i < c->count; i++)
            if (!c->items[i]->users && (oldest == c->count || c->items[i]->used < c->items[oldest]->used))
                oldest = i;
        if (oldest < c->count) {
            kernel_destroy(g, c->items[oldest]);
            c->items[oldest] = c->items[--c->count];
        }
    }
    if (c->count == c->cap) {
        c->cap = c->cap ? 2 * c->cap : 16;
        c->items = util_realloc(c->items, sizeof *c->items * c->cap);
    }
    k = util_malloc(sizeof *k);
    *k = key;
    k->used = c->clock;

    VkDescriptorSetLayoutCreateInfo dlci = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    VkPushConstantRange push = {VK_SHADER_STAGE_COMPUTE_BIT, 0, desc->push_size};
    VkPipelineLayoutCreateInfo plci = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    VkShaderModuleCreateInfo smci = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    VkComputePipelineCreateInfo cpci = {.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    VkShaderModule module;
    dlci.bindingCount = k->num_bindings;
    dlci.pBindings = k->bindings;
    GPU_CHECK(vkCreateDescriptorSetLayout(g->device, &dlci, NULL, &k->set_layout));
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &k->set_layout;
    plci.pushConstantRangeCount = desc->push_size ? 1 : 0;
    plci.pPushConstantRanges = &push;
    GPU_CHECK(vkCreatePipelineLayout(g->device, &plci, NULL, &k->layout));
    /* The module with its constants folded in where that can be done (spirv_specialise.h);
     * the specialisation info goes along either way (an id the module no longer has is
     * ignored). */
    uint32_t *folded = NULL;
    size_t folded_size = 0;
    char why[256] = "";
    static bool warned;
    const bool on_host =
        k->on_host && spirv_specialise(desc->code, desc->code_size, desc->specialization, &folded, &folded_size, why,
                                       sizeof why);
    if (k->on_host && why[0] && !warned) { /* (slower, the same pixels: said once) */
        util_warn("kernel %s: its specialisation constants are left to the driver: %s", desc->name, why);
        warned = true;
    }
    smci.codeSize = on_host ? folded_size : desc->code_size;
    smci.pCode = on_host ? folded : desc->code;
    GPU_CHECK(vkCreateShaderModule(g->device, &smci, NULL, &module));
    free(folded);
    cpci.stage = (VkPipelineShaderStageCreateInfo){VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                                                   NULL, 0, VK_SHADER_STAGE_COMPUTE_BIT, module,
                                                   "main", desc->specialization};
    cpci.layout = k->layout;
    GPU_CHECK(vkCreateComputePipelines(g->device, VK_NULL_HANDLE, 1, &cpci, NULL, &k->pipeline));
    vkDestroyShaderModule(g->device, module, NULL);
    c->items[c->count++] = k;
    return k;
}

void gpu_pipeline_create(gpu *g, gpu_pipeline *p, const gpu_pipeline_desc *desc)
{
    VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 0},
                                     {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 0},
                                     {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 0}};
    VkDescriptorPoolCreateInfo dpci = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    VkDescriptorSetAllocateInfo dsai = {.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};

    assert(desc->num_bindings <= 32);
    memset(p, 0, sizeof *p);
    memcpy(p->local_size, desc->local_size, sizeof p->local_size);
    for (int i = 0; i < 3; i++)
        if (!p->local_size[i])
            p->local_size[i] = 1;
    p->push_size = desc->push_size;
    p->kernel = kernel_get(g, desc);
    p->kernel->users++;
    p->layout = p->kernel->layout;
    p->pipeline = p->kernel->pipeline;

    if (!desc->num_bindings)
        return;
    for (uint32_t i = 0; i < desc->num_bindings; i++)
        for (int k = 0; k < 3; k++)
            sizes[k].descriptorCount += sizes[k].type == desc->bindings[i].type;
    dpci.maxSets = 1;
    dpci.poolSizeCount = 0;
    {
        VkDescriptorPoolSize used[3];
        for (int i = 0; i < 3; i++)
            if (sizes[i].descriptorCount)
                used[dpci.poolSizeCount++] = sizes[i];
        dpci.pPoolSizes = used;
        GPU_CHECK(vkCreateDescriptorPool(g->device, &dpci, NULL, &p->descriptor_pool));
    }
    dsai.descriptorPool = p->descriptor_pool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &p->kernel->set_layout;
    GPU_CHECK(vkAllocateDescriptorSets(g->device, &dsai, &p->set));
    gpu_pipeline_bind(g, p, desc->bindings, desc->num_bindings);
}

void gpu_pipeline_bind(gpu *g, gpu_pipeline *p, const gpu_binding *bindings, uint32_t num_bindings)
{
    VkDescriptorBufferInfo infos[32];
    VkWriteDescriptorSet writes[32];
    assert(num_bindings <= 32 && p->set);
    for (uint32_t i = 0; i < num_bindings; i++) {
        infos[i] = (VkDescriptorBufferInfo){bindings[i].buffer->buffer, 0, VK_WHOLE_SIZE};
        bool texel = bindings[i].type == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        writes[i] = (VkWriteDescriptorSet){VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, NULL, p->set,
                                           bindings[i].binding, 0, 1, bindings[i].type, NULL,
                                           texel ? NULL : &infos[i],
                                           texel ? &bindings[i].buffer->view : NULL};
    }
    vkUpdateDescriptorSets(g->device, num_bindings, writes, 0, NULL);
}

void gpu_pipeline_destroy(gpu *g, gpu_pipeline *p)
{
    if (p->descriptor_pool)
        vkDestroyDescriptorPool(g->device, p->descriptor_pool, NULL);
    if (p->kernel)
        p->kernel->users--; /* (kept for the next pipeline that asks: kernel_get) */
    memset(p, 0, sizeof *p);
}

/* ---- commands ----------------------------------------------------------------------- */

VkCommandBuffer gpu_begin(gpu *g)
{
    VkCommandBufferAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    VkCommandBuffer cmd;
    ai.commandPool = g->pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    GPU_CHECK(vkAllocateCommandBuffers(g->device, &ai, &cmd));
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    GPU_CHECK(vkBeginCommandBuffer(cmd, &bi));
    return cmd;
}

void gpu_dispatch(VkCommandBuffer cmd, const gpu_pipeline *p, const void *push,
                  uint32_t threads_x, uint32_t threads_y, uint32_t threads_z)
{
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->pipeline);
    if (p->set)
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->set,
                                0, NULL);
    if (p->push_size && push)
        vkCmdPushConstants(cmd, p->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, p->push_size, push);
    vkCmdDispatch(cmd, (threads_x + p->local_size[0] - 1) / p->local_size[0],
                  (threads_y + p->local_size[1] - 1) / p->local_size[1],
                  (threads_z + p->local_size[2] - 1) / p->local_size[2]);
}

void gpu_barrier(VkCommandBuffer cmd)
{
    VkMemoryBarrier mb = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                       VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                             VK_PIPELINE_STAGE_HOST_BIT,
                         0, 1, &mb, 0, NULL, 0, NULL);
}

void gpu_submit_wait(gpu *g, VkCommandBuffer cmd)
{
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
    VkFenceCreateInfo fci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    GPU_CHECK(vkEndCommandBuffer(cmd));
    GPU_CHECK(vkCreateFence(g->device, &fci, NULL, &fence));
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    GPU_CHECK(vkQueueSubmit(g->queue, 1, &si, fence));
    GPU_CHECK(vkWaitForFences(g->device, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(g->device, fence, NULL);
    vkFreeCommandBuffers(g->device, g->pool, 1, &cmd);
}
