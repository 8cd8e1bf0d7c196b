/* cluster.c: `bumpbake bake ... --scheduler ADDRESS` runs the command on a
 * Dask cluster through Python's bumpbake.dask (Dask's client speaks only
 * Python). The command is checked and planned here, by the library (every
 * usage error, clash and output path refused before Python starts); what
 * goes to Python is the checked command itself (bb_command_handover, in a
 * memory file whose descriptor Python inherits), which the library sets up
 * there again (bb_command_from_handover): Python parses no option. The
 * process is replaced (one process: its exit code and signals are the
 * command's). Python imports nothing from the working directory (BOOT). */
#define _GNU_SOURCE /* memfd_create */
#include "cluster.h"
#include "cli.h"
#include "common.h"
#include "bumpbake_cluster.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
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

/* /usr/bin/python3 -I -c BOOT N DIR... FD: Python isolated (-I: neither
 * the current directory, nor PYTHONPATH, nor the user's site directory on
 * its path, so a numpy.py, distributed/ or bumpbake/ in the directory being
 * baked is never imported), with the N directories that hold the package
 * put first on its path by BOOT, which then runs the command handed over
 * in descriptor FD (bumpbake.dask._command). */
static const char BOOT[] =
    "import sys\n"
    "n = int(sys.argv[1])\n"
    "sys.path[:0] = dirs = sys.argv[2:2 + n]\n"
    "try:\n"
    "    from bumpbake.dask import _command\n"
    "except ImportError as e:\n"
    "    where = ', '.join(dirs) or 'its own path alone'\n"
    "    print(f'bumpbake: --scheduler: {sys.executable} cannot import bumpbake.dask: {e} "
    "(looked in {where}; BUMPBAKE_PYTHONPATH adds directories)', file=sys.stderr)\n"
    "    sys.exit(1)\n"
    "sys.exit(_command.main(int(sys.argv[2 + n])))\n";

/* A descriptor (inherited across exec) reading the checked command's
 * hand-over from its start; -1 after printing why. A memory file: no size
 * limit (a batch of many inputs), nothing on disk. */
static int handover_fd(const cli_run *r) {
  size_t size = 0;
  char *data = bb_command_handover(r->command, &size);
  if (!data) {
    cli_error_line("out of memory");
    return -1;
  }
  int fd = memfd_create("bumpbake-command", 0);
  size_t done = 0;
  while (fd >= 0 && done < size) {
    const ssize_t n = write(fd, data + done, size - done);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
      break;
    done += (size_t)n;
  }
  free(data);
  if (fd < 0 || done < size || lseek(fd, 0, SEEK_SET) != 0) {
    char line[256];
    snprintf(line, sizeof line, "--scheduler: cannot hand the command over: %s",
             strerror(errno));
    cli_error_line(line);
    if (fd >= 0)
      close(fd);
    return -1;
  }
  return fd;
}

/* The command planned as it would run here (bb_command_plan): a usage
 * error, a clash, an output over an input are the command line's, with its
 * words and exit codes, before Python starts. 0, or the exit code. */
static int plan_here(const cli_run *r) {
  const char *name = bb_command_describe(r->command)->name;
  const bb_command_hooks hooks = {NULL, NULL, NULL, NULL, NULL, NULL}; /* notes: the run's */
  bb_job *job = NULL;
  bb_error err = {{0}};
  const bb_status st = bb_command_plan(r->command, &hooks, &job, &err);
  bb_job_free(job);
  return st == BB_OK ? 0 : cli_library_error(name, st, &err);
}

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

int cli_cluster_exec(const cli_run *r) {
  int rc = plan_here(r);
  if (rc)
    return rc;
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
  const int fd = handover_fd(r);
  if (fd < 0)
    return BB_EXIT_FAILURE;
  char count[16], fd_text[16];
  snprintf(count, sizeof count, "%d", n);
  snprintf(fd_text, sizeof fd_text, "%d", fd);
  int copied = 1;
  for (int i = 0; i < n; i++)
    copied &= dirs[i] != NULL;
  char **args = copied ? calloc((size_t)n + 7, sizeof *args) : NULL;
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
  args[k++] = fd_text;
  fflush(stdout);
  execv(python, args);
  char line[PATH_MAX + 256];
  snprintf(line, sizeof line,
           "--scheduler runs bumpbake.dask in %s, isolated (-I) (Python 3 with "
           "python3-distributed; BUMPBAKE_PYTHON names another): %s",
           python, strerror(errno));
  cli_error_line(line);
  close(fd);
  free(args);
  return BB_EXIT_FAILURE;
}
