/* cluster.c: `bumpbake bake ... --scheduler ADDRESS` hands the command to
 * Python's bumpbake.dask, the one implementation of bakes on a Dask cluster:
 * Dask's client speaks only Python, so the C program execs it with the same
 * arguments (one process, its exit code and signals the command's). */
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

int cli_cluster_exec(int argc, char **argv) {
  const char *python = getenv("BUMPBAKE_PYTHON");
  if (!python || !*python)
    python = "/usr/bin/python3";
  char tree[PATH_MAX];
  if (source_tree_python(tree, sizeof tree)) {
    const char *old = getenv("PYTHONPATH");
    char *path = malloc(strlen(tree) + (old ? strlen(old) : 0) + 2);
    if (!path) {
      cli_error_line("out of memory");
      return BB_EXIT_FAILURE;
    }
    sprintf(path, "%s%s%s", tree, old && *old ? ":" : "", old && *old ? old : "");
    setenv("PYTHONPATH", path, 1);
    free(path);
  }
  char **args = calloc((size_t)argc + 4, sizeof *args);
  if (!args) {
    cli_error_line("out of memory");
    return BB_EXIT_FAILURE;
  }
  args[0] = (char *)python;
  args[1] = "-m";
  args[2] = "bumpbake.dask";
  for (int i = 0; i < argc; i++)
    args[3 + i] = argv[i];
  fflush(stdout);
  execv(python, args);
  char line[PATH_MAX + 256];
  snprintf(line, sizeof line,
           "--scheduler runs %s -m bumpbake.dask (Python 3 with python3-distributed; "
           "BUMPBAKE_PYTHON names another): %s",
           python, strerror(errno));
  cli_error_line(line);
  free(args);
  return BB_EXIT_FAILURE;
}
