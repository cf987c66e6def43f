/* gpu.h: the Vulkan compute layer: instance and device selection, buffers, compute
 * pipelines with one descriptor set, and one-shot command submission.
 *
 * Device choice: discrete GPU, then integrated, then virtual, then CPU (lavapipe), unless
 * an index is given. Every Vulkan call is checked by GPU_CHECK, which stops the program with
 * the call, file, line and VkResult name: a driver failure is not recoverable input. */
#ifndef GONIO_GPU_H
#define GONIO_GPU_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <vulkan/vulkan.h>

#define GPU_CHECK(call) gpu_check((call), #call, __FILE__, __LINE__)
void gpu_check(VkResult r, const char *call, const char *file, int line);
const char *gpu_result_name(VkResult r);

typedef struct gpu_desc {
    int device_index;                   /* -1: pick the best device */
    bool validate;                      /* enable VK_LAYER_KHRONOS_validation */
    const char *const *instance_extensions; /* extra instance extensions (e.g. from GLFW) */
    uint32_t num_instance_extensions;
    bool swapchain;                     /* enable VK_KHR_swapchain on the device */
} gpu_desc;

typedef struct gpu_kernel gpu_kernel;
typedef struct gpu {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice physical;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    VkCommandPool pool;
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties memory;
    bool validate;
    bool unified_memory;                /* one heap that is device-local and host-visible */
    VkDeviceSize max_allocation;        /* maxMemoryAllocationSize (Vulkan 1.1) */
    struct gpu_kernels *kernels;        /* the compiled kernels (gpu_pipeline_create) */
} gpu;

/* Creates instance and device; false with an error message when no usable device exists,
 * the index is out of range, or validation was asked for and the layer is missing. */
bool gpu_create(gpu *g, const gpu_desc *desc);
void gpu_destroy(gpu *g); /* accepts a zeroed struct */

/* The device's limits as gonio applies them, each lowered (never raised) by an environment
 * variable so that tests can reach the code past a limit on small inputs:
 * gpu_storage_limit: the largest storage buffer a kernel may bind, the least of
 * maxStorageBufferRange, maxMemoryAllocationSize and GONIO_MAX_BUFFER_BYTES; *name (may be
 * NULL) gets the name of the one that binds. gpu_host_heap: the size of the heap that
 * host-visible buffers (GPU_MEMORY_HOST) come from. gpu_max_groups: maxComputeWorkGroupCount
 * of an axis, and GONIO_MAX_WORKGROUPS. gpu_max_texels: maxTexelBufferElements, and
 * GONIO_MAX_TEXELS; *name as for gpu_storage_limit. */
VkDeviceSize gpu_storage_limit(const gpu *g, const char **name);
uint32_t gpu_max_texels(const gpu *g, const char **name);
VkDeviceSize gpu_host_heap(const gpu *g);
uint32_t gpu_max_groups(const gpu *g, int axis);

/* Validation messages (warnings and errors) seen since start: the tests require 0. */
int gpu_validation_message_count(void);

/* Prints the device list (index, name, type, API version, ray queries, driver) to stdout. */
bool gpu_print_devices(void);
/* NULL when the device can trace rays from a compute kernel (VK_KHR_ray_query,
 * VK_KHR_acceleration_structure and VK_KHR_deferred_host_operations, with the rayQuery and
 * accelerationStructure features); otherwise what it lacks, in words (a static string). */
const char *gpu_ray_query_missing(VkPhysicalDevice dev);
/* Type name ("discrete", "integrated", "virtual", "cpu", "other"). */
const char *gpu_device_type_name(VkPhysicalDeviceType t);

typedef enum gpu_memory {
    GPU_MEMORY_DEVICE,   /* fastest for the GPU; filled through staging when not host-visible */
    GPU_MEMORY_HOST,     /* host-visible, coherent, persistently mapped (readback, uniforms) */
} gpu_memory;

typedef struct gpu_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize size;
    void *mapped;        /* non-NULL when host-visible */
    VkBufferView view;   /* texel buffers only */
} gpu_buffer;

/* size 0 is allowed and becomes a small dummy buffer (so empty scene arrays can be bound). */
void gpu_buffer_create(gpu *g, gpu_buffer *b, VkDeviceSize size, VkBufferUsageFlags usage,
                       gpu_memory where);
void gpu_buffer_destroy(gpu *g, gpu_buffer *b); /* accepts a zeroed struct */
/* Copies host data in (through a staging buffer when the memory is not mappable). */
void gpu_buffer_upload(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size,
                       VkDeviceSize offset);
void gpu_buffer_download(gpu *g, const gpu_buffer *b, void *data, VkDeviceSize size,
                         VkDeviceSize offset);
void gpu_buffer_fill_zero(gpu *g, gpu_buffer *b);
/* Creates a storage buffer holding `data` (size bytes; NULL data = zeroed). */
void gpu_buffer_create_storage(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size);

/* A uniform texel buffer of RGBA32UI texels (size: bytes, a multiple of 16) holding data
 * (zeros without): read in GLSL through a utextureBuffer with texelFetch, bits unchanged. */
void gpu_buffer_create_texels(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size);
/* The same with texels of another format (size: a multiple of its texel size). */
void gpu_buffer_create_texels_as(gpu *g, gpu_buffer *b, const void *data, VkDeviceSize size,
                                 VkFormat format);

typedef struct gpu_binding {
    uint32_t binding;
    VkDescriptorType type;   /* STORAGE_BUFFER, UNIFORM_BUFFER or UNIFORM_TEXEL_BUFFER */
    const gpu_buffer *buffer;
} gpu_binding;

typedef struct gpu_pipeline_desc {
    const char *name;                 /* for messages */
    const uint32_t *code;             /* SPIR-V, valid as long as the device (the kernel
                                       * cache knows a kernel by this address) */
    size_t code_size;                 /* bytes */
    uint32_t local_size[3];           /* the kernel's work-group size, to round dispatches up */
    uint32_t push_size;               /* bytes of push constants (0: none) */
    const gpu_binding *bindings;
    uint32_t num_bindings;
    const VkSpecializationInfo *specialization;
} gpu_pipeline_desc;

/* A kernel with a descriptor set of its own. The kernel (set layout, layout and pipeline) is
 * the device's, shared by every pipeline made with the same SPIR-V, specialisation, bindings
 * and push constants, and compiled once (gpu.c: the kernel cache). */
typedef struct gpu_pipeline {
    gpu_kernel *kernel;
    VkPipelineLayout layout; /* the kernel's, as its pipeline (read by gpu_dispatch) */
    VkPipeline pipeline;
    VkDescriptorPool descriptor_pool;
    VkDescriptorSet set;
    uint32_t local_size[3];
    uint32_t push_size;
} gpu_pipeline;

void gpu_pipeline_create(gpu *g, gpu_pipeline *p, const gpu_pipeline_desc *desc);
void gpu_pipeline_destroy(gpu *g, gpu_pipeline *p); /* accepts a zeroed struct; keeps the kernel */
/* The kernels the device keeps compiled (those in use, and up to 64 in all). */
uint32_t gpu_kernel_count(const gpu *g);
/* Points the pipeline's descriptor set at these buffers (the bindings and types it was
 * created with): a buffer made anew needs no new kernel, whose compilation costs about a
 * second on lavapipe. Only while no command buffer that uses the set is recording or pending. */
void gpu_pipeline_bind(gpu *g, gpu_pipeline *p, const gpu_binding *bindings, uint32_t num_bindings);

/* One-shot command buffers: begin, record dispatches and barriers, submit and wait. */
VkCommandBuffer gpu_begin(gpu *g);
/* Dispatches enough work groups to cover threads_x * threads_y * threads_z invocations. */
void gpu_dispatch(VkCommandBuffer cmd, const gpu_pipeline *p, const void *push,
                  uint32_t threads_x, uint32_t threads_y, uint32_t threads_z);
/* Compute-to-compute (and compute-to-transfer) memory barrier. */
void gpu_barrier(VkCommandBuffer cmd);
void gpu_submit_wait(gpu *g, VkCommandBuffer cmd);

#endif
