/* The smallest engine of the installed plugin: found through pkg-config or CMake (tests/tests/install.rs),
 * it creates a context on a headless device of the plugin's own, prints the device and destroys it.
 * Exit code 0 only if every call returned HRTS_RESULT_OK. */
#include <hrts.h>

#include <stdio.h>
#include <string.h>

static int check(HrtsResult result, const char *call, const HrtsContext *context) {
  if (result == HRTS_RESULT_OK) {
    return 1;
  }
  fprintf(stderr, "hrts consumer: %s failed: %s (%s)\n", call, hrts_result_name((int32_t)result),
          hrts_last_error(context));
  return 0;
}

int main(void) {
  HrtsContextCreateInfo info;
  HrtsCapabilities caps;
  HrtsContext *context = NULL;
  int ok;

  if (hrts_get_api_version() != HRTS_API_VERSION) {
    fprintf(stderr, "hrts consumer: library API version %u, header %u\n", (unsigned)hrts_get_api_version(),
            (unsigned)HRTS_API_VERSION);
    return 1;
  }

  memset(&info, 0, sizeof info);
  info.struct_size = (uint32_t)sizeof info;
  info.api_version = HRTS_API_VERSION;
  info.vulkan = NULL;
  info.device_name_filter = NULL;
  info.enable_validation = false;
  if (!check(hrts_context_create(&info, &context), "hrts_context_create", NULL)) {
    return 1;
  }

  memset(&caps, 0, sizeof caps);
  caps.struct_size = (uint32_t)sizeof caps;
  ok = check(hrts_get_capabilities(context, &caps), "hrts_get_capabilities", context);
  if (ok) {
    printf("hrts consumer: device \"%s\", conservative raster tier %u\n", caps.device_name,
           (unsigned)caps.conservative_raster_tier);
  }
  ok = check(hrts_context_destroy(context), "hrts_context_destroy", NULL) && ok;
  return ok ? 0 : 1;
}
