/* vmt.c: Source material files (.vmt) naming a bake's VTF textures. */

#include "core/internal.h"
#include "files/file_identity.h"
#include "files/safe_file.h"
#include "texture/texture.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* path made absolute against the working directory, with "." and ".."
 * resolved and repeated slashes dropped, lexically (no symbolic link is
 * followed: the file need not exist yet), into out. 0 on success. */
static int absolute_path(const char *path, char *out, size_t cap) {
  char joined[2 * PATH_MAX];
  if (path[0] == '/') {
    if (snprintf(joined, sizeof joined, "%s", path) >= (int)sizeof joined)
      return -1;
  } else {
    char cwd[PATH_MAX];
    if (!getcwd(cwd, sizeof cwd))
      return -1;
    if (snprintf(joined, sizeof joined, "%s/%s", cwd, path) >= (int)sizeof joined)
      return -1;
  }
  size_t k = 0;
  out[0] = '\0';
  for (char *s = joined; *s;) {
    while (*s == '/')
      s++;
    char *end = strchr(s, '/');
    size_t n = end ? (size_t)(end - s) : strlen(s);
    if (n == 0)
      break;
    if (n == 1 && s[0] == '.') {
      /* nothing */
    } else if (n == 2 && s[0] == '.' && s[1] == '.') {
      while (k > 0 && out[k - 1] != '/')
        k--;
      if (k > 0)
        k--;
      out[k] = '\0';
    } else {
      if (k + 1 + n + 1 > cap)
        return -1;
      out[k++] = '/';
      memcpy(out + k, s, n);
      k += n;
      out[k] = '\0';
    }
    s += n;
  }
  if (k == 0) {
    if (cap < 2)
      return -1;
    out[0] = '/', out[1] = '\0';
  }
  return 0;
}

/* The name Source looks texture up by: its path relative to materials,
 * without ".vtf", into out. what names it in messages. */
static bb_status texture_name(const char *materials, const char *texture, const char *what,
                              char *out, size_t cap, bb_error *err) {
  for (const char *c = texture; *c; c++)
    if (*c == '"' || (unsigned char)*c < 0x20)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: a material cannot quote the %s's path (it has a '\"' or a "
                      "control character)",
                      texture, what);
  const size_t len = strlen(texture);
  if (len < 4 || strcasecmp(texture + len - 4, ".vtf") != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the %s of a material must be a .vtf file",
                    texture, what);
  char dir[PATH_MAX], file[PATH_MAX];
  if (absolute_path(materials, dir, sizeof dir) != 0 ||
      absolute_path(texture, file, sizeof file) != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: path too long", texture);
  size_t d = strlen(dir);
  if (d == 1) /* materials is "/" */
    d = 0;
  if (strncmp(file, dir, d) != 0 || file[d] != '/' || strlen(file) <= d + 5)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s: the %s is not inside the materials folder %s, where Source looks",
                    texture, what, materials);
  const char *rel = file + d + 1;
  const size_t n = strlen(rel) - 4; /* without ".vtf" */
  if (n + 1 > cap)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: path too long", texture);
  memcpy(out, rel, n);
  out[n] = '\0';
  return BB_OK;
}

/* The nearest folder named "materials" (any case) above the bump map, into
 * out: where a game's tree keeps its materials. 0 when found. */
static int find_materials(const char *bumpmap, char *out, size_t cap) {
  char file[PATH_MAX];
  if (absolute_path(bumpmap, file, sizeof file) != 0)
    return -1;
  char *slash = strrchr(file, '/');
  while (slash && slash != file) {
    *slash = '\0';
    const char *name = strrchr(file, '/');
    name = name ? name + 1 : file;
    if (strcasecmp(name, "materials") == 0) {
      if (strlen(file) + 1 > cap)
        return -1;
      memcpy(out, file, strlen(file) + 1);
      return 0;
    }
    slash = strrchr(file, '/');
  }
  return -1;
}

/* 1 when a and b both exist and are one file (hard links, a symbolic
 * link to the other, a directory spelled two ways). */
static int same_existing_file(const char *a, const char *b) {
  if (!a || !b)
    return 0;
  const bb__file_identity ia = bb__file_identify(a), ib = bb__file_identify(b);
  return ia.exists && ib.exists && bb__same_file_identity(&ia, &ib);
}

/* The material's own name: a .vmt, and not a texture it names (a texture
 * ends in .vtf, so only another name of the same file can be one). */
static bb_status check_material_path(const char *path, const bb_vmt_options *o, bb_error *err) {
  const size_t len = strlen(path);
  if (len < 4 || strcasecmp(path + len - 4, ".vmt") != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: a Source material's name ends in .vmt", path);
  if (same_existing_file(path, o->bumpmap) || same_existing_file(path, o->basetexture))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the material would overwrite the texture %s",
                    path, same_existing_file(path, o->bumpmap) ? o->bumpmap : o->basetexture);
  return BB_OK;
}

bb_status bb__vmt_text(const char *path, const bb_vmt_options *o, char **text, size_t *size,
                      bb_error *err) {
  if (text)
    *text = NULL;
  if (size)
    *size = 0;
  if (!path || !*path)
    return bb__fail(err, BB_ERR_ARGUMENT, "material: no path");
  if (!text || !size)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: bb__vmt_text: NULL argument", path);
  if (!o || !o->bumpmap || !*o->bumpmap)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: a material needs its bump map's .vtf", path);
  bb_status checked = check_material_path(path, o, err);
  if (checked != BB_OK)
    return checked;
  char found[PATH_MAX];
  const char *materials = o->materials_dir;
  if (!materials || !*materials) {
    if (find_materials(o->bumpmap, found, sizeof found) != 0)
      return bb__fail(
          err, BB_ERR_ARGUMENT,
          "%s: no folder named \"materials\" above %s: name the game's materials "
          "folder with --materials DIR",
          path, o->bumpmap);
    materials = found;
  }
  char bump[PATH_MAX], base[PATH_MAX];
  bb_status st = texture_name(materials, o->bumpmap, "bump map", bump, sizeof bump, err);
  if (st == BB_OK && o->basetexture)
    st = texture_name(materials, o->basetexture, "base texture", base, sizeof base, err);
  if (st != BB_OK)
    return st;
  const size_t cap = 3 * PATH_MAX + 256;
  char *out = malloc(cap);
  if (!out)
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  int n = snprintf(out, cap, "// Source material written by bumpbake %s\n"
                             "\"LightmappedGeneric\"\n{\n",
                   BB_VERSION_STRING);
  if (o->basetexture)
    n += snprintf(out + n, cap - (size_t)n, "\t\"$basetexture\" \"%s\"\n", base);
  n += snprintf(out + n, cap - (size_t)n, "\t\"$bumpmap\" \"%s\"\n", bump);
  if (o->ssbump)
    n += snprintf(out + n, cap - (size_t)n, "\t\"$ssbump\" \"1\"\n");
  n += snprintf(out + n, cap - (size_t)n, "}\n");
  *text = out;
  *size = (size_t)n;
  return BB_OK;
}

bb_status bb_vmt_write(const char *path, const bb_vmt_options *o, bb_error *err) {
  char *text = NULL;
  size_t size = 0;
  bb_status st = bb__vmt_text(path, o, &text, &size, err);
  if (st == BB_OK)
    st = bb__file_write(path, text, size, err);
  free(text);
  return st;
}
