/* cluster.c: `bumpbake bake ... --scheduler ADDRESS` hands the command to
 * Python's bumpbake.dask, the one implementation of bakes on a Dask cluster:
 * Dask's client speaks only Python, so the C program execs it with the same
 * arguments (one process, its exit code and signals the command's). Python
 * imports nothing from the working directory (BOOT, below). */
#include "cluster.h"
#include "cli.h"
#include "common.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* DIR/python when this program is DIR/build/bumpbake (or DIR/build/x/...)
 * of a source tree holding the package, into out; 0 when it is not. */
static int source_tree_python(char *out, size_t cap) {
  char exe[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0)
    return 0;
  exe[n] = '\0';
  for (int up = 0; up < 3; up++) { /* build/bumpbake, build/debug/bumpbake */
    char *slash = strrchr(exe, '/');
    if (!slash)
      return 0;
    *slash = '\0';
    char probe[PATH_MAX + 64];
    snprintf(probe, sizeof probe, "%s/python/bumpbake/dask/__init__.py", exe);
    struct stat st;
    if (stat(probe, &st) == 0 && snprintf(out, cap, "%s/python", exe) < (int)cap)
      return 1;
  }
  return 0;
}

/* /usr/bin/python3 -I -c BOOT N DIR... bake ARGS...: Python isolated (-I:
 * neither the current directory, nor PYTHONPATH, nor the user's site
 * directory on its path, so a numpy.py, distributed/ or bumpbake/ in the
 * directory being baked is never imported), with the N directories that
 * hold the package put first on its path by BOOT, which then runs
 * bumpbake.dask as `python3 -m` would, with the arguments after them. */
static const char BOOT[] =
    "import sys\n"
    "n = int(sys.argv[1])\n"
    "sys.path[:0] = dirs = sys.argv[2:2 + n]\n"
    "del sys.argv[1:2 + n]\n"
    "try:\n"
    "    import bumpbake.dask._cli\n"
    "except ImportError as e:\n"
    "    where = ', '.join(dirs) or 'its own path alone'\n"
    "    print(f'bumpbake: --scheduler: {sys.executable} cannot import bumpbake.dask: {e} "
    "(looked in {where}; BUMPBAKE_PYTHONPATH adds directories)', file=sys.stderr)\n"
    "    sys.exit(1)\n"
    "import runpy\n"
    "runpy.run_module('bumpbake.dask', run_name='__main__', alter_sys=True)\n";

/* Appends the absolute directories of BUMPBAKE_PYTHONPATH (empty entries,
 * which would mean the current directory to Python, are skipped) to dirs
 * (malloc'd copies); -1 after printing why for a relative one. */
static int env_python_dirs(char **dirs, int *n, int cap) {
  const char *list = getenv("BUMPBAKE_PYTHONPATH");
  for (const char *p = list; p && *p;) {
    const size_t len = strcspn(p, ":");
    if (len > 0 && *n < cap) {
      if (*p != '/') {
        cli_error_line("BUMPBAKE_PYTHONPATH: every directory must be an absolute path");
        return -1;
      }
      dirs[(*n)++] = strndup(p, len);
    }
    p += len + (p[len] == ':');
  }
  return 0;
}

int cli_cluster_exec(int argc, char **argv) {
  const char *python = getenv("BUMPBAKE_PYTHON");
  if (!python || !*python)
    python = "/usr/bin/python3";
  /* Where the package is: BUMPBAKE_PYTHONPATH's directories, this source
   * tree's python/, where make install put it. */
  enum { MAX_DIRS = 64 };
  char *dirs[MAX_DIRS + 2];
  int n = 0;
  if (env_python_dirs(dirs, &n, MAX_DIRS) != 0)
    return BB_EXIT_FAILURE;
  char tree[PATH_MAX];
  struct stat st;
  if (source_tree_python(tree, sizeof tree))
    dirs[n++] = strdup(tree);
  else if (*cli_installed_python_dir() && stat(cli_installed_python_dir(), &st) == 0)
    dirs[n++] = strdup(cli_installed_python_dir());
  char count[16];
  snprintf(count, sizeof count, "%d", n);
  int copied = 1;
  for (int i = 0; i < n; i++)
    copied &= dirs[i] != NULL;
  char **args = copied ? calloc((size_t)argc + (size_t)n + 6, sizeof *args) : NULL;
  if (!args) {
    cli_error_line("out of memory");
    return BB_EXIT_FAILURE;
  }
  int k = 0;
  args[k++] = (char *)python;
  args[k++] = "-I";
  args[k++] = "-c";
  args[k++] = (char *)BOOT;
  args[k++] = count;
  for (int i = 0; i < n; i++)
    args[k++] = dirs[i];
  for (int i = 0; i < argc; i++)
    args[k++] = argv[i];
  fflush(stdout);
  execv(python, args);
  char line[PATH_MAX + 256];
  snprintf(line, sizeof line,
           "--scheduler runs bumpbake.dask in %s, isolated (-I) (Python 3 with "
           "python3-distributed; BUMPBAKE_PYTHON names another): %s",
           python, strerror(errno));
  cli_error_line(line);
  free(args);
  return BB_EXIT_FAILURE;
}
