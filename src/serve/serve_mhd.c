/* serve_mhd.c: libmicrohttpd loaded by its soname when serve starts
 * (serve_mhd.h says why), every call serve makes looked up once. */
#define SERVE_MHD_LOADER
#include "serve_mhd.h"

#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#ifndef BB_MHD_SONAME
#define BB_MHD_SONAME "libmicrohttpd.so.12"
#endif

serve_mhd_calls serve_mhd;

static char failure[512];

static void load(void) {
  void *lib = dlopen(BB_MHD_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    const char *why = dlerror();
    snprintf(failure, sizeof failure, "cannot load %s: %s", BB_MHD_SONAME,
             why ? why : "unknown error");
    return;
  }
  serve_mhd_calls calls;
  memset(&calls, 0, sizeof calls);
  /* The ISO C cast of a data pointer to a function pointer, as POSIX allows. */
#define SERVE_MHD_LOOKUP(name)                                                                \
  *(void **)&calls.name = dlsym(lib, #name);                                                  \
  if (!calls.name) {                                                                          \
    snprintf(failure, sizeof failure, "cannot load %s: it has no %s", BB_MHD_SONAME, #name);  \
    return;                                                                                   \
  }
  SERVE_MHD_CALLS(SERVE_MHD_LOOKUP)
#undef SERVE_MHD_LOOKUP
  serve_mhd = calls;
}

int serve_mhd_load(char *why, size_t cap) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, load);
  if (serve_mhd.MHD_start_daemon) return 1;
  snprintf(why, cap, "%s", failure);
  return 0;
}
