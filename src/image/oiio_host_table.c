/* oiio_host_table.c: in the OpenImageIO module, the library's host table
 * (oiio_module.h), set by the module's entry (render/oiio_entry.c) and
 * called through by oiio_host.c; a file of its own because the fuzz
 * targets, which link the module's objects with the library's, keep it and
 * leave oiio_host.c out. */
#include "image/oiio_module.h"

const bb__oiio_host *bb__oiio_host_table;
