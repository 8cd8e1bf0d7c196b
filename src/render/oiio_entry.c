/* oiio_entry.c: the OpenImageIO module's one export (image/oiio_module.h):
 * it keeps the library's host table, which image/oiio_host.c calls
 * through, and hands back the module's calls. It is in the render family,
 * the highest whose calls the module carries (text.h, over image's). */
#include "image/oiio_module.h"

#include "render/text.h"

#include <string.h>

#define BB__OIIO_ENTRY_ADDRESS(ret, name, params, args, fallback) name,
static const bb__oiio_table calls = {
    sizeof(bb__oiio_table), BB_VERSION_STRING, BB__OIIO_IMAGE_CALLS(BB__OIIO_ENTRY_ADDRESS)
        BB__OIIO_TEXT_CALLS(BB__OIIO_ENTRY_ADDRESS) bb__oiio_gif_abort};

const bb__oiio_table *bb__oiio_module_entry(const bb__oiio_host *host) {
  if (!host || host->size != sizeof *host || strcmp(host->version, BB_VERSION_STRING) != 0)
    return NULL;
  bb__oiio_host_table = host;
  return &calls;
}
