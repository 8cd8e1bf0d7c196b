/* texture_quality.c: writes engine textures and measures what block
 * compression costs them, for tools/bench_blocks.sh.
 *
 *   texture_quality write IN OUT [--format F] [--map plain|normal|ssbump]
 *                   [--fast] [--no-mips] [--threads N] [--vtf-version N]
 *       IN (any image) to OUT: .vtf or .dds by bb__texture_write, any other
 *       extension by bb__image_write (8-bit; normal maps stored signed);
 *       prints the seconds the write took (in this process, start-up
 *       excluded).
 *   texture_quality decode IN OUT.png [--level K]
 *       level K of IN to an 8-bit PNG, to look at: a .vtf through the tests'
 *       own decoder (tests/texture/texture_oracle.h: DXT1, DXT5, BGR888,
 *       BGRA8888), anything else (.dds) through OpenImageIO.
 *   texture_quality compare REF DECODED [--map ...] [--channels N] [--level K]
 *       DECODED (.vtf as above, else OpenImageIO: a DDS, a PNG) against REF,
 *       the float map (normal maps as N, compared as 0.5 + 0.5 N): PSNR,
 *       max and mean error in 8-bit code units over the first N channels
 *       (default: REF's, or 3 for a grey REF against colour); for normal
 *       maps also the angle between the decoded (renormalised) and true
 *       normals, and the error of z alone. --level K compares DECODED's mip
 *       level K with level K of REF's chain (bb_mip_chain, normals
 *       renormalised). One line: "psnr_db P max_codes M mean_codes E
 *       [angle_mean_deg A angle_max_deg B z_max_codes Z]".
 */
#include "bumpbake.h"
#include "texture/texture_oracle.h"
#include "core/internal.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "texture/texture.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(const char *what, const bb_error *err) {
  fprintf(stderr, "texture_quality: %s%s%s\n", what, err ? ": " : "", err ? err->message : "");
  return 1;
}

static const char *ext_of(const char *path) {
  const char *dot = strrchr(path, '.');
  return dot ? dot : "";
}

/* The whole file, malloc'd. */
static unsigned char *slurp(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  if (!f)
    return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *data = n > 0 ? malloc((size_t)n) : NULL;
  if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
    free(data);
    data = NULL;
  }
  fclose(f);
  *size = (size_t)(n > 0 ? n : 0);
  return data;
}

/* Level `level` of a VTF decoded by the oracle into a 4-channel image in
 * [0, 1]. */
static int read_vtf(const char *path, int level, bb_image *out) {
  size_t size;
  unsigned char *file = slurp(path, &size);
  if (!file)
    return fail(path, NULL);
  int w, h;
  size_t at = oracle_vtf_level_offset(file, size, level, &w, &h);
  const int code = size >= 56 ? (int)oracle_u32(file + 52) : -1;
  if (!at || bb_image_alloc(out, w, h, 4, NULL) != BB_OK) {
    free(file);
    return fail("not a VTF level the oracle reads", NULL);
  }
  unsigned char *rgba = malloc((size_t)w * (size_t)h * 4);
  const unsigned char *d = file + at;
  const size_t n = (size_t)w * (size_t)h;
  if (code == 13 || code == 15) {
    oracle_decode(code == 13 ? ORACLE_BC1 : ORACLE_BC3, d, w, h, rgba);
  } else if (code == 3 || code == 12) {
    const size_t step = code == 3 ? 3 : 4;
    for (size_t i = 0; i < n; i++) {
      rgba[4 * i + 0] = d[step * i + 2];
      rgba[4 * i + 1] = d[step * i + 1];
      rgba[4 * i + 2] = d[step * i + 0];
      rgba[4 * i + 3] = code == 12 ? d[step * i + 3] : 255;
    }
  } else {
    free(rgba);
    free(file);
    bb_image_free(out);
    return fail("VTF format the oracle does not decode", NULL);
  }
  for (size_t i = 0; i < n * 4; i++)
    out->pixels[i] = (float)rgba[i] / 255.0f;
  free(rgba);
  free(file);
  return 0;
}

static int read_any(const char *path, int level, bb_image *out) {
  if (strcasecmp(ext_of(path), ".vtf") == 0)
    return read_vtf(path, level, out);
  bb_error err;
  if (bb__image_read_mip(path, level, out, NULL, NULL, &err) != BB_OK)
    return fail(path, &err);
  return 0;
}

/* A map kind as the library names it (plain, normal, ssbump, ...). */
static int parse_map(const char *name, bb_map_kind *map) {
  return bb__map_kind_parse(name, map, NULL) == BB_OK ? 0 : -1;
}

static int cmd_write(int argc, char **argv) {
  if (argc < 2)
    return fail("write IN OUT [options]", NULL);
  bb_texture_options o;
  bb_texture_options_init(&o);
  bb_error err;
  for (int i = 2; i < argc; i++) {
    if (strcmp(argv[i], "--format") == 0 && i + 1 < argc) {
      if (bb__texture_format_parse(argv[++i], &o.format, &err) != BB_OK)
        return fail("--format", &err);
    } else if (strcmp(argv[i], "--map") == 0 && i + 1 < argc) {
      if (parse_map(argv[++i], &o.map) != 0)
        return fail("--map plain|normal|ssbump", NULL);
    } else if (strcmp(argv[i], "--fast") == 0) {
      o.fast = 1;
    } else if (strcmp(argv[i], "--no-mips") == 0) {
      o.mips = 0;
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      o.threads = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--vtf-version") == 0 && i + 1 < argc) {
      o.vtf_version = atoi(argv[++i]);
    } else {
      return fail(argv[i], NULL);
    }
  }
  bb_image img = {0};
  if (bb_image_read(argv[0], &img, NULL, &err) != BB_OK)
    return fail(argv[0], &err);
  const double t0 = now();
  bb_status st;
  if (bb__path_is_texture_format(argv[1])) {
    st = bb__texture_write(argv[1], &img, &o, &err);
  } else {
    bb_write_options w = {BB_DEPTH_DEFAULT,
                          bb_map_kind_get(o.map)->range, NULL, NULL};
    st = bb__image_write(argv[1], &img, &w, &err);
  }
  const double seconds = now() - t0;
  bb_image_free(&img);
  if (st != BB_OK)
    return fail(argv[1], &err);
  printf("%.3f\n", seconds);
  return 0;
}

static int cmd_decode(int argc, char **argv) {
  int level = argc >= 4 && strcmp(argv[2], "--level") == 0 ? atoi(argv[3]) : 0;
  if (argc < 2)
    return fail("decode IN OUT.png [--level K]", NULL);
  bb_image img = {0};
  if (read_any(argv[0], level, &img) != 0)
    return 1;
  /* An 8-bit PNG of at most R, G, B (alpha would hide the colours). */
  bb_image rgb = {0};
  bb_error err;
  const int c = img.channels >= 3 ? 3 : img.channels;
  if (bb_image_alloc(&rgb, img.width, img.height, c, &err) != BB_OK)
    return fail("decode", &err);
  for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; i++)
    for (int k = 0; k < c; k++)
      rgb.pixels[i * (size_t)c + (size_t)k] = img.pixels[i * (size_t)img.channels + (size_t)k];
  bb_write_options w = {BB_DEPTH_8, BB_RANGE_UNIT, NULL, NULL};
  bb_status st = bb__image_write(argv[1], &rgb, &w, &err);
  bb_image_free(&img);
  bb_image_free(&rgb);
  return st == BB_OK ? 0 : fail(argv[1], &err);
}

static int cmd_compare(int argc, char **argv) {
  if (argc < 2)
    return fail("compare REF DECODED [--map M] [--channels N] [--level K]", NULL);
  bb_map_kind map = BB_MAP_PLAIN;
  int channels = 0, level = 0;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (strcmp(argv[i], "--map") == 0) {
      if (parse_map(argv[i + 1], &map) != 0)
        return fail("--map plain|normal|ssbump", NULL);
    } else if (strcmp(argv[i], "--channels") == 0) {
      channels = atoi(argv[i + 1]);
    } else if (strcmp(argv[i], "--level") == 0) {
      level = atoi(argv[i + 1]);
    } else {
      return fail(argv[i], NULL);
    }
  }
  bb_image ref = {0}, dec = {0};
  bb_error err;
  if (bb_image_read(argv[0], &ref, NULL, &err) != BB_OK)
    return fail(argv[0], &err);
  if (level > 0) {
    bb_image *chain = NULL;
    int count = 0;
    if (bb_mip_chain(&ref, bb_map_kind_get(map)->unit_vectors ? BB_MIP_RENORMALIZE : BB_MIP_AVERAGE,
                     &chain, &count, &err) != BB_OK)
      return fail(argv[0], &err);
    if (level >= count)
      return fail("--level past the chain's last level", NULL);
    bb_image_free(&ref);
    ref = chain[level];
    chain[level] = (bb_image){0};
    bb_mip_chain_free(chain, count);
  }
  if (read_any(argv[1], level, &dec) != 0)
    return 1;
  if (ref.width != dec.width || ref.height != dec.height)
    return fail("sizes differ", NULL);
  if (channels <= 0)
    channels = ref.channels == 1 && dec.channels >= 3 ? 3 : ref.channels;
  if (channels > dec.channels)
    channels = dec.channels;
  const int normal = bb_map_kind_get(map)->unit_vectors;
  double se = 0, sum = 0, max = 0, angle_sum = 0, angle_max = 0, z_max = 0;
  size_t n = (size_t)ref.width * (size_t)ref.height, samples = 0;
  for (size_t i = 0; i < n; i++) {
    const float *r = ref.pixels + i * (size_t)ref.channels;
    const float *d = dec.pixels + i * (size_t)dec.channels;
    for (int k = 0; k < channels; k++) {
      double want = r[ref.channels == 1 ? 0 : k];
      if (normal)
        want = 0.5 + 0.5 * want;
      want = want < 0 ? 0 : want > 1 ? 1 : want;
      const double e = fabs((double)d[k] - want) * 255.0;
      se += e * e;
      sum += e;
      max = e > max ? e : max;
      samples++;
    }
    if (normal && dec.channels >= 3 && ref.channels >= 3) {
      double v[3], len = 0, dot = 0;
      for (int k = 0; k < 3; k++) {
        v[k] = 2.0 * (double)d[k] - 1.0;
        len += v[k] * v[k];
      }
      len = sqrt(len);
      for (int k = 0; k < 3; k++)
        dot += (len > 0 ? v[k] / len : (k == 2)) * (double)r[k];
      dot = dot > 1 ? 1 : dot < -1 ? -1 : dot;
      const double a = acos(dot) * 180.0 / 3.14159265358979323846;
      angle_sum += a;
      angle_max = a > angle_max ? a : angle_max;
      const double ez = fabs((double)d[2] - (0.5 + 0.5 * (double)r[2])) * 255.0;
      z_max = ez > z_max ? ez : z_max;
    }
  }
  const double mse = se / (double)samples;
  printf("psnr_db %.2f max_codes %.1f mean_codes %.3f",
         mse > 0 ? 10.0 * log10(255.0 * 255.0 / mse) : 99.0, max, sum / (double)samples);
  if (normal && dec.channels >= 3)
    printf(" angle_mean_deg %.3f angle_max_deg %.2f z_max_codes %.1f", angle_sum / (double)n,
           angle_max, z_max);
  else if (normal)
    printf(" (x and y only: the file holds no z)");
  printf("\n");
  bb_image_free(&ref);
  bb_image_free(&dec);
  return 0;
}

int main(int argc, char **argv) {
  if (argc >= 2 && strcmp(argv[1], "write") == 0)
    return cmd_write(argc - 2, argv + 2);
  if (argc >= 2 && strcmp(argv[1], "decode") == 0)
    return cmd_decode(argc - 2, argv + 2);
  if (argc >= 2 && strcmp(argv[1], "compare") == 0)
    return cmd_compare(argc - 2, argv + 2);
  fprintf(stderr, "usage: texture_quality write|decode|compare ... (see the file's head)\n");
  return 2;
}
