/* cmd_devices.c: `gonio devices`, the Vulkan devices gonio can use. */
#include "cli.h"
#include "gpu.h"

int cmd_devices(int argc, char **argv)
{
    const cli_command cmd = {
        .name = "devices",
        .intro = "Lists the Vulkan devices: index (for --device), name, type, API version, whether\n"
                 "it has ray queries (VK_KHR_ray_query with VK_KHR_acceleration_structure; what it\n"
                 "lacks is said under the table), and the driver with its version.\n"
                 "Without --device, gonio picks a discrete GPU, then an integrated one, then the CPU\n"
                 "(lavapipe).\n"};
    cli_args args;
    int rc = cli_parse(&cmd, argc, argv, &args);
    if (rc >= 0)
        return rc;
    return gpu_print_devices() ? 0 : 1;
}
