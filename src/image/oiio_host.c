/* oiio_host.c: in the OpenImageIO module only, the library's functions its
 * C++ files call (oiio_module.h's host list), each a call through the
 * table the library handed to bb__oiio_module_entry (render/oiio_entry.c): the
 * module shares the library's state (staged files, limits) rather than
 * having copies. The fuzz targets link the module's objects with the
 * library's and leave this file out. */
#include "image/oiio_module.h"

#include <stdarg.h>
#include <stdio.h>

#define BB__OIIO_HOST_SHIM(ret, name, params, args)                                           \
  ret name params { return bb__oiio_host_table->name args; }
BB__OIIO_HOST_CALLS(BB__OIIO_HOST_SHIM)

/* bb__fail formats here, into a message as long as the library's, which
 * bb__fail_message then passes through bb__fail unchanged. */
bb_status bb__fail(bb_error *err, bb_status status, const char *fmt, ...) {
  char message[sizeof err->message];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(message, sizeof message, fmt, ap);
  va_end(ap);
  return bb__oiio_host_table->bb__fail_message(err, status, message);
}
