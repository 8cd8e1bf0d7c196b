/* make_seeds.c: writes the seed corpora of the fuzz targets from the
 * project's own fixtures and small patterns, so no binary seed is committed:
 *   make_seeds FIXTURES_DIR OUT_DIR
 * OUT_DIR/load: every small fixture PNG as it is and as TGA, TIFF and EXR,
 * and a small valid file of every other format OpenImageIO writes here
 * (JPEG, progressive JPEG, BMP, PNM, GIF, HDR, DPX, JPEG 2000, WebP, SGI,
 * ICO; through seed_formats.cpp), 16-bit, half and mip-mapped files, a
 * GIF of three frames, and the engine textures bumpbake writes (a VTF of
 * every format, version 7.2 and 7.5, with and without mips; a DDS of every
 * format), each after fuzz_load's leading byte; OUT_DIR/compare: pairs of
 * small images; OUT_DIR/provenance: the provenance texts of the golden
 * EXRs, in pairs; OUT_DIR/cli: the command lines of the docs' examples;
 * OUT_DIR/mesh: small models of each format fuzz_mesh reads. */
#include "bumpbake.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "mesh/mesh_internal.h"
#include "texture/texture.h"

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

/* fuzz_load's leading byte: extension index in the low 5 bits (its
 * EXTENSIONS; 15 .dds, 16 .vtf), channel rule 0 (auto) above. */
static const char *const LOAD_EXT[16] = {".png", ".tga", ".tif", ".exr", ".jpg", ".bmp",
                                         ".pnm", ".gif", ".hdr", ".dpx", ".jp2", ".webp",
                                         ".sgi", ".ico", ".psd", ".dds"};

/* OpenImageIO's writer of the formats bumpbake does not write (seed_formats.cpp). */
int seed_write(const char *path, const float *pixels, int width, int height, int channels,
               const char *flag);

/* Saves the file at tmp as a load seed of extension index k, then removes
 * it; returns 1 when it was small enough to be a seed. */
static int keep_seed(const char *dir, const char *name, const char *tmp, unsigned char k) {
  size_t size;
  unsigned char *bytes = read_all(tmp, &size);
  unlink(tmp);
  if (!bytes)
    return 0;
  write_seed(dir, name, &k, 1, bytes, size);
  free(bytes);
  return 1;
}

/* A small image of c channels: a ramp, a ring and a checker, so each
 * channel differs and compressors have something to do. */
static bb_image pattern(int w, int h, int c) {
  bb_image img;
  if (bb_image_alloc(&img, w, h, c, NULL) != BB_OK)
    exit(1);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int ch = 0; ch < c; ch++) {
        float v = ch % 3 == 0   ? (float)x / (float)(w - 1)
                  : ch % 3 == 1 ? (float)((x - w / 2) * (x - w / 2) + (y - h / 2) * (y - h / 2)) /
                                      (float)(w * w / 4 + h * h / 4)
                                : (float)((x / 4 + y / 4) % 2);
        img.pixels[((size_t)y * (size_t)w + (size_t)x) * (size_t)c + (size_t)ch] =
            ch == 3 ? 1.0f - v * 0.5f : v;
      }
  return img;
}

/* The engine textures: a VTF of every format bumpbake writes, in versions
 * 7.2 and 7.5 (the resource dictionary), with and without mips; a DDS of
 * every format (legacy header, and DX10 for the floats). 16 x 16, of 3 and
 * 4 channels (a format refusing one is skipped). */
static int texture_seeds(const char *dir, const char *out) {
  static const bb_texture_format vtf[] = {BB_TEXTURE_FORMAT_BC1, BB_TEXTURE_FORMAT_BC3,
                                          BB_TEXTURE_FORMAT_BGR8, BB_TEXTURE_FORMAT_BGRA8,
                                          BB_TEXTURE_FORMAT_RGBA16F};
  static const bb_texture_format dds[] = {
      BB_TEXTURE_FORMAT_BC1,   BB_TEXTURE_FORMAT_BC3,     BB_TEXTURE_FORMAT_BC4,
      BB_TEXTURE_FORMAT_BC5,   BB_TEXTURE_FORMAT_RGBA8,   BB_TEXTURE_FORMAT_RGBA16F,
      BB_TEXTURE_FORMAT_RGBA32F};
  char tmp[1024], name[64];
  int written = 0;
  for (int c = 1; c <= 4; c++) {
    bb_image img = pattern(16, 16, c);
    for (size_t f = 0; f < sizeof vtf / sizeof vtf[0]; f++)
      for (int version = 2; version <= 5; version += 3)
        for (int mips = 0; mips <= 1; mips++) {
          bb_texture_options o;
          bb_texture_options_init(&o);
          o.format = vtf[f];
          o.vtf_version = version;
          o.mips = mips;
          o.fast = 1;
          o.description = "seed=1";
          snprintf(tmp, sizeof tmp, "%s/seed.vtf", out);
          snprintf(name, sizeof name, "texture%d_%s_7.%d%s.vtf", c,
                   bb__texture_format_name(vtf[f]), version, mips ? "_mips" : "");
          if (bb__texture_write(tmp, &img, &o, NULL) == BB_OK)
            written += keep_seed(dir, name, tmp, 16);
        }
    for (size_t f = 0; f < sizeof dds / sizeof dds[0]; f++) {
      bb_texture_options o;
      bb_texture_options_init(&o);
      o.format = dds[f];
      o.map = dds[f] == BB_TEXTURE_FORMAT_BC5 ? BB_MAP_NORMAL : BB_MAP_PLAIN;
      o.fast = 1;
      snprintf(tmp, sizeof tmp, "%s/seed.dds", out);
      snprintf(name, sizeof name, "texture%d_%s.dds", c, bb__texture_format_name(dds[f]));
      if (bb__texture_write(tmp, &img, &o, NULL) == BB_OK)
        written += keep_seed(dir, name, tmp, 15);
    }
    bb_image_free(&img);
  }
  return written;
}

static void load_seeds(const char *fixtures, const char *out) {
  char dir[1024], tmp[1024];
  make_dir(out, "load", dir, sizeof dir);
  DIR *d = opendir(fixtures);
  if (!d)
    exit(1);
  int n = 0, written = 0;
  /* The small fixtures as they are, and as bumpbake writes TGA, TIFF and EXR. */
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
      snprintf(name, sizeof name, "%s%s", e->d_name, LOAD_EXT[k]);
      if (k == 0) {
        write_seed(dir, name, &k, 1, bytes, size);
        written++;
        continue;
      }
      snprintf(tmp, sizeof tmp, "%s/seed%s", out, LOAD_EXT[k]);
      if (bb__image_write(tmp, &img, NULL, &err) == BB_OK)
        written += keep_seed(dir, name, tmp, k);
    }
    bb_image_free(&img);
    free(bytes);
    n++;
  }
  closedir(d);

  /* Every other format OpenImageIO writes here, from small patterns of 1, 3
   * and 4 channels (a format refusing one is skipped), and the variants a
   * reader takes another path for. */
  for (int c = 1; c <= 4; c++) {
    if (c == 2)
      continue;
    bb_image img = pattern(24, 16, c);
    /* OpenJPEG's default of 6 resolutions needs 32 texels a side. */
    bb_image large = pattern(64, 40, c);
    for (unsigned char k = 4; k < 16; k++) {
      const bb_image *src = strcmp(LOAD_EXT[k], ".jp2") == 0 ? &large : &img;
      char name[64];
      snprintf(tmp, sizeof tmp, "%s/seed%s", out, LOAD_EXT[k]);
      snprintf(name, sizeof name, "pattern%d%s", c, LOAD_EXT[k]);
      if (seed_write(tmp, src->pixels, src->width, src->height, c, NULL) == 0)
        written += keep_seed(dir, name, tmp, k);
      else
        unlink(tmp);
    }
    bb_image_free(&large);
    snprintf(tmp, sizeof tmp, "%s/seed.jpg", out);
    if (seed_write(tmp, img.pixels, img.width, img.height, c, "jpeg:progressive") == 0) {
      char name[64];
      snprintf(name, sizeof name, "progressive%d.jpg", c);
      written += keep_seed(dir, name, tmp, 4);
    }
    /* 16-bit PNG and TIFF, half EXR, and mip-mapped TIFF and EXR. */
    const struct {
      const char *ext;
      bb_depth depth;
      unsigned char k;
    } depths[] = {{".png", BB_DEPTH_16, 0}, {".tif", BB_DEPTH_16, 2}, {".exr", BB_DEPTH_HALF, 3}};
    for (size_t i = 0; i < sizeof depths / sizeof depths[0]; i++) {
      bb_write_options o = {depths[i].depth, BB_RANGE_UNIT, "seed", NULL};
      char name[64];
      snprintf(tmp, sizeof tmp, "%s/seed%s", out, depths[i].ext);
      snprintf(name, sizeof name, "depth%d%s", c, depths[i].ext);
      if (bb__image_write(tmp, &img, &o, NULL) == BB_OK)
        written += keep_seed(dir, name, tmp, depths[i].k);
    }
    bb_image *levels = NULL;
    int count = 0;
    if (bb_mip_chain(&img, BB_MIP_AVERAGE, &levels, &count, NULL) == BB_OK) {
      for (unsigned char k = 2; k <= 3; k++) {
        char name[64];
        snprintf(tmp, sizeof tmp, "%s/seed%s", out, LOAD_EXT[k]);
        snprintf(name, sizeof name, "mips%d%s", c, LOAD_EXT[k]);
        if (bb__image_write_mips(tmp, levels, count, NULL, NULL) == BB_OK)
          written += keep_seed(dir, name, tmp, k);
      }
      bb_mip_chain_free(levels, count);
    }
    bb_image_free(&img);
  }
  /* A GIF of three frames. */
  bb_image frame = pattern(16, 12, 3);
  bb_animation *a = NULL;
  snprintf(tmp, sizeof tmp, "%s/seed.gif", out);
  if (bb__animation_open(tmp, 16, 12, 10.0, &a, NULL) == BB_OK) {
    int ok = 1;
    for (int f = 0; f < 3 && ok; f++) {
      for (size_t i = 0; i < 16u * 12u * 3u; i++)
        frame.pixels[i] = 1.0f - frame.pixels[i];
      ok = bb__animation_add_frame(a, &frame, NULL) == BB_OK;
    }
    if (ok && bb__animation_close(a, NULL) == BB_OK)
      written += keep_seed(dir, "frames.gif", tmp, 7);
    else if (!ok)
      bb__animation_abort(a);
  }
  bb_image_free(&frame);
  written += texture_seeds(dir, out);
  printf("make_seeds: %d load seeds (%d fixtures, and every format OpenImageIO writes)\n",
         written, n);
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
  if (bb__mesh_alloc(&part, 3 * n, n, m->normals != NULL, &err) != BB_OK) {
    fprintf(stderr, "make_seeds: %s\n", err.message);
    exit(1);
  }
  for (size_t i = 0; i < 3 * n; i++) {
    memcpy(part.positions + 3 * i, m->positions + 3 * (size_t)m->indices[i], 3 * sizeof(float));
    if (m->normals)
      memcpy(part.normals + 3 * i, m->normals + 3 * (size_t)m->indices[i], 3 * sizeof(float));
    part.indices[i] = (uint32_t)i;
  }
  if (bb__mesh_write(path, &part, &err) != BB_OK) {
    fprintf(stderr, "make_seeds: %s\n", err.message);
    exit(1);
  }
  bb__mesh_free(&part);
}

static void mesh_seeds(const char *fixtures, const char *out) {
  char dir[1024], model[1024], tmp[1100];
  make_dir(out, "mesh", dir, sizeof dir);
  snprintf(model, sizeof model, "%s/rivet_panel.obj", fixtures);
  bb_mesh panel;
  bb_error err;
  if (bb__mesh_load(model, &panel, &err) != BB_OK) {
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
  bb__mesh_free(&panel);
  const unsigned char gltf_lead = 0x01, tiled_gltf_lead = 0x89, dae_lead = 0x02;
  write_seed(dir, "quad.gltf", &gltf_lead, 1, SEED_GLTF, sizeof SEED_GLTF - 1);
  write_seed(dir, "tiled.gltf", &tiled_gltf_lead, 1, SEED_GLTF, sizeof SEED_GLTF - 1);
  write_seed(dir, "quad.dae", &dae_lead, 1, SEED_DAE, sizeof SEED_DAE - 1);
}

/* Text seeds, one file per string: fuzz_basis's basis files and
 * fuzz_program's image programs (the images it names are the target's). */
static void text_seeds(const char *out, const char *name, const char *const *texts,
                       size_t n) {
  char dir[1024];
  make_dir(out, name, dir, sizeof dir);
  for (size_t i = 0; i < n; i++) {
    char file[32];
    snprintf(file, sizeof file, "seed%zu", i);
    write_seed(dir, file, texts[i], strlen(texts[i]), NULL, 0);
  }
}

static void basis_seeds(const char *out) {
  static const char *const texts[] = {
      "# Half-Life 2's basis\n0.816497 0 0.57735\n-0.408248 0.707107 0.57735\n"
      "-0.408248 -0.707107 0.57735\n",
      "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n",
      "1, 0, 0.5\n0, 1, 0.5 # comma separated\n-1, -1, 0.5\n",
      "0 0 1\n0 0 1\n1 0 0\n",
      "1e308 0 1\nnan 0 1\n0 inf 1\n"};
  text_seeds(out, "basis", texts, sizeof texts / sizeof texts[0]);
}

static void program_seeds(const char *out) {
  static const char *const texts[] = {
      "heightmap(a.png, 4)",
      "addnormals(heightmap(a.png, 2), heightmap(d.tif, 8))",
      "smoothnormals(heightmap(c.exr, 1))",
      "add(b.tga, scale(c.exr, 0.5, 0.5, 0.5, 1))",
      "invertColor(makeIntensity(e.png))",
      "makeAlpha(invertAlpha(b.tga))",
      "addnormals(_flat, heightmap(e.png, 3))",
      "heightmap(../outside.png, 4)"};
  text_seeds(out, "program", texts, sizeof texts / sizeof texts[0]);
}

/* fuzz_print: a leading byte (how many of the last bytes name the file),
 * then a description: bumpbake's own provenance, another tool's, and one
 * with an escape sequence, a bidi override and a C1 control in it. */
static void print_seeds(const char *out) {
  static const char *const texts[] = {
      "\x04" "bumpbake 0.2.0\nkind: ssbump\ncommand: bumpbake bake h.png --scale 4\n"
      "input: h.png sha256:00\nbasis: hl2\n_name",
      "\x00" "Created with GIMP",
      "\x03" "kind: normal\ncommand: \x1b]0;title\x07 \xe2\x80\xae evil \xc2\x9b 31m\nred"};
  char dir[1024];
  make_dir(out, "print", dir, sizeof dir);
  for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
    char file[32];
    snprintf(file, sizeof file, "seed%zu", i);
    /* The second seed's leading byte is a NUL: strlen would stop at it. */
    size_t n = i == 1 ? 1 + strlen(texts[i] + 1) : strlen(texts[i]);
    write_seed(dir, file, texts[i], n, NULL, 0);
  }
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
  basis_seeds(argv[2]);
  program_seeds(argv[2]);
  print_seeds(argv[2]);
  return 0;
}
