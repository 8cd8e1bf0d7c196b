/* text_calls.c: the text the render family draws (text.h), passed on to
 * the OpenImageIO module (image/oiio_module.h; render/oiio_text.cpp there),
 * which is loaded on the first call. */
#include "image/oiio_module.h"
#include "render/text.h"

#include <stddef.h>

#define BB__TEXT_WRAPPER(ret, name, params, args, fallback)                                   \
  ret name params {                                                                           \
    const bb__oiio_table *t = bb__oiio_module();                                              \
    if (!t) fallback;                                                                         \
    return t->name args;                                                                      \
  }
BB__OIIO_TEXT_CALLS(BB__TEXT_WRAPPER)
