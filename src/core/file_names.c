/* file_names.c: a path's last component and its extension (file_names.h). */
#include "core/file_names.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

const char *bb__file_name(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

void bb__directory_part(const char *path, char *dir, size_t cap) {
  const char *slash = strrchr(path, '/');
  if (!slash)
    snprintf(dir, cap, ".");
  else if (slash == path)
    snprintf(dir, cap, "/");
  else
    snprintf(dir, cap, "%.*s", (int)(slash - path), path);
}

const char *bb__file_extension(const char *path) {
  if (!path)
    return NULL;
  const char *name = bb__file_name(path), *dot = strrchr(name, '.');
  return dot && dot > name ? dot : NULL;
}

int bb__path_has_extension(const char *path, const char *ext) {
  const char *dot = bb__file_extension(path);
  return dot && strcasecmp(dot + 1, ext) == 0;
}
