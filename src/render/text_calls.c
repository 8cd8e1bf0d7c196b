/* text_calls.c: the text the render family draws (text.h), passed on to
 * the OpenImageIO module (image/oiio_module.h; render/oiio_text.cpp there),
 * which is loaded on the first call. */
#include "image/oiio_module.h"
#include "render/text.h"

#include <stddef.h>

/* Linked into the program (the fuzz targets: BB_OIIO_LINKED), the module's
 * own definitions are the program's: no wrapper. */
#ifndef BB_OIIO_LINKED
BB__OIIO_TEXT_CALLS(BB__OIIO_WRAPPER)
#endif
