/* oiio_load.c: the library's side of the OpenImageIO module (oiio_module.h):
 * the module loaded on the first call that needs it, once per process, and
 * the image family's OpenImageIO calls (oiio_calls.h) passed on to it.
 *
 * Where the module is: beside the library. libbumpbake.so finds it in its
 * own folder (dladdr, the path the dynamic linker loaded it from, made
 * absolute when the library is loaded); a program that linked libbumpbake.a
 * in the folder compiled into it (bb__oiio_module_dir: the build folder for
 * the build's archive, LIBDIR for the installed one and the installed
 * program). Never from the working directory or the environment: a
 * process reading an image must not load code a user put there. */
#define _GNU_SOURCE /* dladdr1, RTLD_DL_LINKMAP */

#include "image/oiio_module.h"

#include "image/png_hooks.h"

#include <dlfcn.h>
#include <limits.h>
#include <link.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

/* The folder compiled in for a static link (oiio_module_dir.c). */
extern const char bb__oiio_module_dir[];

static const bb__oiio_table *table;
/* Why the module could not be loaded (bb__fail cuts it to a message). */
static char failure[PATH_MAX + 512];
/* libbumpbake.so's name as loaded, and its folder, absolute; empty in a
 * program that linked the archive. */
static char shared_name[PATH_MAX];
static char shared_dir[PATH_MAX];

/* At load, while a relative name the library was loaded by still means
 * what it meant: the shared library's own folder. */
__attribute__((constructor)) static void find_own_folder(void) {
  Dl_info info;
  struct link_map *map = NULL;
  if (!dladdr1((const void *)&find_own_folder, &info, (void **)&map, RTLD_DL_LINKMAP) ||
      !info.dli_fname || !map || !map->l_prev) /* the program itself: the archive */
    return;
  char real[PATH_MAX];
  if (!realpath(info.dli_fname, real)) return;
  char *slash = strrchr(real, '/');
  if (!slash || strlen(info.dli_fname) >= sizeof shared_name) return;
  *slash = '\0';
  snprintf(shared_dir, sizeof shared_dir, "%s", slash == real ? "/" : real);
  snprintf(shared_name, sizeof shared_name, "%s", info.dli_fname);
}

#define BB__OIIO_HOST_ENTRY(ret, name, params, args) name,
static const bb__oiio_host host = {sizeof(bb__oiio_host), BB_VERSION_STRING,
                                   BB__OIIO_HOST_CALLS(BB__OIIO_HOST_ENTRY)};

bb_status bb__fail_message(bb_error *err, bb_status status, const char *message) {
  return bb__fail(err, status, "%s", message);
}

#ifndef BB_OIIO_LINKED
/* The address space the module takes once loaded: OpenImageIO's libraries,
 * what their constructors allocate and the threads they start (VmSize of a
 * process before and after its first image read: 47,880 and 484,120 KiB on
 * Debian 12, OpenImageIO 2.4.7, 2026-12-07), with a margin. Under a lower
 * RLIMIT_AS, a library's constructor throwing std::bad_alloc inside
 * dlopen() ends the process (abort), so the load is refused first. */
#define MODULE_ADDRESS_SPACE ((unsigned long long)448 << 20)

/* 1 when RLIMIT_AS leaves the module room; else says why in failure. */
static int address_space_left(const char *path) {
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return 1;
  unsigned long long pages = 0;
  FILE *f = fopen("/proc/self/statm", "r");
  const int read = f && fscanf(f, "%llu", &pages) == 1;
  if (f) fclose(f);
  if (!read) return 1; /* unknown: let dlopen try */
  const unsigned long long used = pages * (unsigned long long)sysconf(_SC_PAGESIZE);
  const unsigned long long left = rl.rlim_cur > used ? rl.rlim_cur - used : 0;
  if (left >= MODULE_ADDRESS_SPACE) return 1;
  snprintf(failure, sizeof failure,
           "cannot load bumpbake's image module %s: out of memory (it takes about %llu MiB of "
           "address space; %llu MiB is left under RLIMIT_AS)",
           path, MODULE_ADDRESS_SPACE >> 20, left >> 20);
  return 0;
}
#endif

#ifdef BB_OIIO_LINKED
/* The fuzz targets link the module's objects into the program. */
static void load(void) {
  (void)bb__png_hooks_set();
  table = bb__oiio_module_entry(&host);
}
#else
static void load(void) {
  /* A program linking libbumpbake.a gets png_hooks.c from here. */
  (void)bb__png_hooks_set();
  char path[PATH_MAX + 64];
  const char *dir = shared_dir[0] ? shared_dir : bb__oiio_module_dir;
  snprintf(path, sizeof path, "%s/%s%s", dir, BB__OIIO_MODULE_PREFIX, BB_VERSION_STRING);
  /* The shared library joins the global scope, so that OpenImageIO's calls
   * to libpng from the module reach its hooks (png_hooks.c) first, as when
   * it linked OpenImageIO itself. */
  if (!address_space_left(path)) return;
  if (shared_name[0]) (void)dlopen(shared_name, RTLD_LAZY | RTLD_NOLOAD | RTLD_GLOBAL);
  void *module = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!module) {
    const char *why = dlerror();
    /* An mmap the address-space limit refused (RLIMIT_AS, ulimit -v). */
    if (why && (strstr(why, "failed to map segment") || strstr(why, "annot allocate memory")))
      snprintf(failure, sizeof failure,
               "cannot load bumpbake's image module %s: out of memory (%s)", path, why);
    else if (why && strstr(why, path) == why)
      snprintf(failure, sizeof failure, "cannot load bumpbake's image module: %s", why);
    else
      snprintf(failure, sizeof failure, "cannot load bumpbake's image module %s: %s", path,
               why ? why : "unknown error");
    return;
  }
  const bb__oiio_table *(*entry)(const bb__oiio_host *);
  *(void **)&entry = dlsym(module, BB__OIIO_ENTRY);
  const bb__oiio_table *t = entry ? entry(&host) : NULL;
  if (!t || t->size != sizeof *t || strcmp(t->version, BB_VERSION_STRING) != 0) {
    snprintf(failure, sizeof failure,
             "cannot load bumpbake's image module %s: not the module of bumpbake %s", path,
             BB_VERSION_STRING);
    return;
  }
  table = t;
}
#endif

const bb__oiio_table *bb__oiio_module(void) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, load);
  return table;
}

bb_status bb__oiio_failed(bb_error *err) { return bb__fail(err, BB_ERR_IO, "%s", failure); }

/* Linked into the program (the fuzz targets), the module's own definitions
 * of these calls are the program's: no wrapper. */
#ifndef BB_OIIO_LINKED
BB__OIIO_IMAGE_CALLS(BB__OIIO_WRAPPER)

void bb__oiio_gif_abort(bb_animation *a) {
  const bb__oiio_table *t = bb__oiio_module();
  if (t) t->bb__oiio_gif_abort(a);
}
#endif
