/* make_seeds.c: writes the seed corpora of the fuzz targets from the
 * project's own fixtures, so no binary seed is committed:
 *   make_seeds FIXTURES_DIR OUT_DIR
 * OUT_DIR/load: every small fixture PNG as it is, and each converted to TGA,
 * TIFF and EXR (with fuzz_load's leading byte); OUT_DIR/compare: pairs of
 * small images; OUT_DIR/provenance: the provenance texts of the golden
 * EXRs, in pairs; OUT_DIR/cli: the command lines of the docs' examples;
 * OUT_DIR/mesh: small models of each format fuzz_mesh reads. */
#include "bumpbake.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { MAX_SEED_BYTES = 32 * 1024 };

static void write_seed(const char *dir, const char *name, const void *a, size_t na,
                       const void *b, size_t nb) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f || fwrite(a, 1, na, f) != na || (nb && fwrite(b, 1, nb, f) != nb) ||
      fclose(f) != 0) {
    fprintf(stderr, "make_seeds: %s: %s\n", path, strerror(errno));
    exit(1);
  }
}

static unsigned char *read_all(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  if (!f)
    return NULL;
  unsigned char *buf = malloc(MAX_SEED_BYTES + 1);
  *size = buf ? fread(buf, 1, MAX_SEED_BYTES + 1, f) : 0;
  fclose(f);
  if (buf && *size > MAX_SEED_BYTES) {
    free(buf);
    return NULL;
  }
  return buf;
}

static void make_dir(const char *out, const char *name, char *dir, size_t cap) {
  snprintf(dir, cap, "%s/%s", out, name);
  if (mkdir(dir, 0755) != 0 && errno != EEXIST) {
    fprintf(stderr, "make_seeds: %s: %s\n", dir, strerror(errno));
    exit(1);
  }
}

/* fuzz_load's leading byte: extension index (png, tga, tif, exr) in the low
 * two bits, channel rule above. */
static void load_seeds(const char *fixtures, const char *out) {
  static const char *const EXT[] = {".png", ".tga", ".tif", ".exr"};
  char dir[1024], tmp[1024];
  make_dir(out, "load", dir, sizeof dir);
  DIR *d = opendir(fixtures);
  if (!d)
    exit(1);
  int n = 0;
  for (struct dirent *e; (e = readdir(d)) != NULL;) {
    size_t len = strlen(e->d_name);
    if (len < 5 || strcmp(e->d_name + len - 4, ".png") != 0)
      continue;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", fixtures, e->d_name);
    size_t size;
    unsigned char *bytes = read_all(path, &size);
    if (!bytes)
      continue; /* too big to be a useful seed */
    bb_image img;
    bb_error err;
    if (bb_image_read(path, &img, NULL, &err) != BB_OK) {
      fprintf(stderr, "make_seeds: %s\n", err.message);
      exit(1);
    }
    for (unsigned char k = 0; k < 4; k++) {
      char name[300];
      snprintf(name, sizeof name, "%s%s", e->d_name, EXT[k]);
      if (k == 0) {
        write_seed(dir, name, &k, 1, bytes, size);
        continue;
      }
      snprintf(tmp, sizeof tmp, "%s/seed%s", out, EXT[k]);
      size_t converted_size;
      unsigned char *converted = NULL;
      if (bb_image_write(tmp, &img, NULL, &err) == BB_OK)
        converted = read_all(tmp, &converted_size);
      unlink(tmp);
      if (converted)
        write_seed(dir, name, &k, 1, converted, converted_size);
      free(converted);
    }
    bb_image_free(&img);
    free(bytes);
    n++;
  }
  closedir(d);
  printf("make_seeds: %d fixtures x 4 formats for load\n", n);
}

/* fuzz_compare's layout: w-1, h-1, c-1, fail, warn, then the floats. */
static void compare_seeds(const char *out) {
  char dir[1024];
  make_dir(out, "compare", dir, sizeof dir);
  unsigned char seed[3 + 8 + 2 * 4 * 4 * 3 * 4];
  for (int s = 0; s < 3; s++) {
    memset(seed, 0, sizeof seed);
    seed[0] = 3, seed[1] = 3, seed[2] = 2; /* 4 x 4, 3 channels */
    float thresholds[2] = {1e-6f, s == 2 ? 0.5f : 1.0f};
    memcpy(seed + 3, thresholds, sizeof thresholds);
    for (int i = 0; i < 2 * 48; i++) {
      float v =
          (float)((i * 37 + s * 11) % 97) / 97.0f + (s == 1 && i == 60 ? 0.25f : 0.0f);
      memcpy(seed + 11 + 4 * i, &v, sizeof v);
    }
    char name[32];
    snprintf(name, sizeof name, "pair%d", s);
    write_seed(dir, name, seed, sizeof seed, NULL, 0);
  }
}

/* Two provenance texts joined by a NUL, after fuzz_provenance's capacity byte. */
static void provenance_seeds(const char *fixtures, const char *out) {
  char dir[1024], goldens[1024];
  make_dir(out, "provenance", dir, sizeof dir);
  snprintf(goldens, sizeof goldens, "%s/goldens", fixtures);
  char *texts[8];
  int n = 0;
  DIR *d = opendir(goldens);
  for (struct dirent *e; d && n < 8 && (e = readdir(d)) != NULL;) {
    if (!strstr(e->d_name, ".exr"))
      continue;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", goldens, e->d_name);
    int w, h, c;
    bb_image_info info;
    bb_error err;
    if (bb_image_read_info(path, &w, &h, &c, &info, &err) == BB_OK && info.description)
      texts[n++] = info.description; /* owned here from now on */
  }
  if (d)
    closedir(d);
  for (int i = 0; i < n; i++) {
    char name[32];
    unsigned char cap = (unsigned char)(5 + i);
    size_t na = strlen(texts[i]), nb = strlen(texts[(i + 1) % n]);
    unsigned char *buf = malloc(1 + na + 1 + nb);
    buf[0] = cap;
    memcpy(buf + 1, texts[i], na + 1);
    memcpy(buf + 2 + na, texts[(i + 1) % n], nb);
    snprintf(name, sizeof name, "pair%d", i);
    write_seed(dir, name, buf, 1 + na + 1 + nb, NULL, 0);
    free(buf);
  }
  for (int i = 0; i < n; i++)
    free(texts[i]);
  printf("make_seeds: %d provenance texts\n", n);
}

/* fuzz_cli's layout: the command's index, then NUL-separated arguments. */
static void cli_seeds(const char *out) {
  static const char *const LINES[] = {
      "\001h.png\0--scale\0"
      "64\0-o\0rock",
      "\001h.png\0--scale\0"
      "64\0--ssbump\0s.exr\0--json\0--rays\0"
      "16",
      "\001h.png\0--scale\0"
      "8\0--normal\0n.png\0--ao\0a.png\0--depth\0"
      "16\0--clamp",
      "\000h.png\0-o\0n.png\0--scale\0"
      "64\0--normal-y\0up\0--channel\0luma",
      "\002-r\0"
      "32\0-n\0-A\0h.tga\0"
      "4",
      "\002-D\0-d\0-f\0"
      "3\0h.tga\0"
      "2",
      "\003a.exr\0b.exr\0--fail\0"
      "1e-5\0--diff\0d.exr\0--json",
      "\003a.png\0b.png\0--warn\0"
      "0.1\0--warnpercent\0"
      "5",
      "\004h.png",
      "\001--help",
      "\005-size\0"
      "64\0"
      "32\0m.obj",
      "\006h.png\0--scale\0"
      "8\0-o\0r.png\0--light\0"
      "45,30",
      "\007h.png\0--scale\0"
      "8\0-o\0s.png",
      "\010n.png\0-o\0s.tga\0--mips",
      "\011s.png\0-o\0n.exr",
      "\012a.png\0b.png\0-o\0c.png\0--mix\0"
      "0.5",
      "\013addnormals(a.tga, heightmap(b.tga, 4))\0-o\0p.png",
  };
  static const size_t SIZES[] = {
      sizeof "\001h.png\0--scale\0"
             "64\0-o\0rock",
      sizeof "\001h.png\0--scale\0"
             "64\0--ssbump\0s.exr\0--json\0--rays\0"
             "16",
      sizeof "\001h.png\0--scale\0"
             "8\0--normal\0n.png\0--ao\0a.png\0--depth\0"
             "16\0--clamp",
      sizeof "\000h.png\0-o\0n.png\0--scale\0"
             "64\0--normal-y\0up\0--channel\0luma",
      sizeof "\002-r\0"
             "32\0-n\0-A\0h.tga\0"
             "4",
      sizeof "\002-D\0-d\0-f\0"
             "3\0h.tga\0"
             "2",
      sizeof "\003a.exr\0b.exr\0--fail\0"
             "1e-5\0--diff\0d.exr\0--json",
      sizeof "\003a.png\0b.png\0--warn\0"
             "0.1\0--warnpercent\0"
             "5",
      sizeof "\004h.png",
      sizeof "\001--help",
      sizeof "\005-size\0"
             "64\0"
             "32\0m.obj",
      sizeof "\006h.png\0--scale\0"
             "8\0-o\0r.png\0--light\0"
             "45,30",
      sizeof "\007h.png\0--scale\0"
             "8\0-o\0s.png",
      sizeof "\010n.png\0-o\0s.tga\0--mips",
      sizeof "\011s.png\0-o\0n.exr",
      sizeof "\012a.png\0b.png\0-o\0c.png\0--mix\0"
             "0.5",
      sizeof "\013addnormals(a.tga, heightmap(b.tga, 4))\0-o\0p.png",
  };
  char dir[1024];
  make_dir(out, "cli", dir, sizeof dir);
  for (size_t i = 0; i < sizeof LINES / sizeof LINES[0]; i++) {
    char name[32];
    snprintf(name, sizeof name, "line%zu", i);
    write_seed(dir, name, LINES[i], SIZES[i] - 2, NULL, 0); /* no final NUL pair */
  }
}

/* fuzz_mesh's leading byte: the format (obj, gltf, dae, glb) in the low two
 * bits, the render's axis and tiling above. Seeds: the first triangles of
 * the rivet panel fixture, written as OBJ and binary glTF by the library's
 * own exporter, and a glTF (a node hierarchy, normals, 16-bit indices in a
 * data: URI) and a Collada file of one quad, as text. */
static const char SEED_GLTF[] =
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"chi"
    "ldren\":[1],\"translation\":[0,0.5,0]},{\"mesh\":0,\"scale\":[1,1,2]}],\"meshes\":[{\""
    "primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],\"buffer"
    "s\":[{\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAA"
    "AAAAAAACAPwAAAAAAAIA/AAAAAAAAAAAAAIA/AAAAAAAAgL8AAAAAAAAAAAAAgL8AAAAAAAAAAAA"
    "AgL8AAAAAAAAAAAAAgL8AAAAAAAABAAIAAAACAAMA\",\"byteLength\":108}],\"bufferViews\":"
    "[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"by"
    "teLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":12}],\"accessors\":[{\"b"
    "ufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],\"max"
    "\":[1,0,1]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},{\"b"
    "ufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}";

static const char SEED_DAE[] =
    "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
    "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
    "<asset><unit name=\"meter\" meter=\"1\"/><up_axis>Z_UP</up_axis></asset>\n"
    "<library_geometries><geometry id=\"q\"><mesh>\n"
    "<source id=\"q-p\"><float_array id=\"q-a\" count=\"12\">0 0 0 1 0 0 1 0 1 0 0 1"
    "</float_array>\n"
    "<technique_common><accessor source=\"#q-a\" count=\"4\" stride=\"3\">"
    "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
    "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
    "<vertices id=\"q-v\"><input semantic=\"POSITION\" source=\"#q-p\"/></vertices>\n"
    "<polylist count=\"1\"><input semantic=\"VERTEX\" source=\"#q-v\" offset=\"0\"/>"
    "<vcount>4</vcount><p>0 1 2 3</p></polylist>\n"
    "</mesh></geometry></library_geometries>\n"
    "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\">"
    "<matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix>"
    "<instance_geometry url=\"#q\"/></node></visual_scene></library_visual_scenes>\n"
    "<scene><instance_visual_scene url=\"#s\"/></scene>\n"
    "</COLLADA>\n";

/* Writes the first `triangles` of m (their vertices renumbered) to path. */
static void write_part(const bb_mesh *m, size_t triangles, const char *path) {
  bb_mesh part;
  bb_error err;
  size_t n = triangles < m->triangle_count ? triangles : m->triangle_count;
  if (bb_mesh_alloc(&part, 3 * n, n, m->normals != NULL, &err) != BB_OK) {
    fprintf(stderr, "make_seeds: %s\n", err.message);
    exit(1);
  }
  for (size_t i = 0; i < 3 * n; i++) {
    memcpy(part.positions + 3 * i, m->positions + 3 * (size_t)m->indices[i], 3 * sizeof(float));
    if (m->normals)
      memcpy(part.normals + 3 * i, m->normals + 3 * (size_t)m->indices[i], 3 * sizeof(float));
    part.indices[i] = (uint32_t)i;
  }
  if (bb_mesh_write(path, &part, &err) != BB_OK) {
    fprintf(stderr, "make_seeds: %s\n", err.message);
    exit(1);
  }
  bb_mesh_free(&part);
}

static void mesh_seeds(const char *fixtures, const char *out) {
  char dir[1024], model[1024], tmp[1100];
  make_dir(out, "mesh", dir, sizeof dir);
  snprintf(model, sizeof model, "%s/rivet_panel.obj", fixtures);
  bb_mesh panel;
  bb_error err;
  if (bb_mesh_load(model, &panel, &err) != BB_OK) {
    fprintf(stderr, "make_seeds: %s\n", err.message);
    exit(1);
  }
  static const char *const KINDS[] = {"part.obj", "part.glb"};
  static const unsigned char LEAD[] = {0x00, 0x83};
  for (int k = 0; k < 2; k++) {
    snprintf(tmp, sizeof tmp, "%s/.%s", dir, KINDS[k]);
    write_part(&panel, 60, tmp);
    size_t size;
    unsigned char *bytes = read_all(tmp, &size);
    if (!bytes || remove(tmp) != 0) {
      fprintf(stderr, "make_seeds: %s: cannot read back\n", tmp);
      exit(1);
    }
    write_seed(dir, KINDS[k], &LEAD[k], 1, bytes, size);
    free(bytes);
  }
  bb_mesh_free(&panel);
  const unsigned char gltf_lead = 0x01, tiled_gltf_lead = 0x89, dae_lead = 0x02;
  write_seed(dir, "quad.gltf", &gltf_lead, 1, SEED_GLTF, sizeof SEED_GLTF - 1);
  write_seed(dir, "tiled.gltf", &tiled_gltf_lead, 1, SEED_GLTF, sizeof SEED_GLTF - 1);
  write_seed(dir, "quad.dae", &dae_lead, 1, SEED_DAE, sizeof SEED_DAE - 1);
}

int main(int argc, char **argv) {

  if (argc != 3) {
    fprintf(stderr, "usage: make_seeds FIXTURES_DIR OUT_DIR\n");
    return 2;
  }
  if (mkdir(argv[2], 0755) != 0 && errno != EEXIST) {
    fprintf(stderr, "make_seeds: %s: %s\n", argv[2], strerror(errno));
    return 1;
  }
  load_seeds(argv[1], argv[2]);
  compare_seeds(argv[2]);
  provenance_seeds(argv[1], argv[2]);
  cli_seeds(argv[2]);
  mesh_seeds(argv[1], argv[2]);
  return 0;
}
