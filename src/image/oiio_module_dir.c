/* oiio_module_dir.c: the folder a program that linked libbumpbake.a loads
 * the OpenImageIO module from (oiio_load.c), compiled in: the build folder
 * for the build's archive and programs, LIBDIR for the installed ones (the
 * Makefile compiles this file once for each). */
#ifndef BB_OIIO_MODULE_DIR
#error "BB_OIIO_MODULE_DIR: the folder of libbumpbake-oiio.so (the Makefile sets it)"
#endif

extern const char bb__oiio_module_dir[];
const char bb__oiio_module_dir[] = BB_OIIO_MODULE_DIR;
