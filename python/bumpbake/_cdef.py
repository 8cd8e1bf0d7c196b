"""The part of include/bumpbake.h the Python package calls, for cffi.

Kept to what read(), bake() and normal() need. The structs must match the header
field for field, since cffi's ABI mode lays them out from these
declarations: tests/test_cdef.py compiles a C program against the real
header and checks every size, offset, enum value and function signature
declared here, so a change to the header fails that test, naming what to
update. Copy declarations from the header as they are (comments dropped).
"""

# Types, in header order.
TYPES = """
typedef enum bb_status {
  BB_OK = 0,
  BB_ERR_ARGUMENT,
  BB_ERR_IO,
  BB_ERR_FORMAT,
  BB_ERR_SIZE,
  BB_ERR_VALUE,
  BB_ERR_MEMORY,
  BB_ERR_CANCELLED
} bb_status;

typedef struct bb_error {
  char message[512];
} bb_error;

typedef struct bb_image {
  int width;
  int height;
  int channels;
  float *pixels;
} bb_image;

typedef struct bb_image_info {
  int alpha_channel;
  int is_float;
  int bits_per_sample;
  char format_name[32];
  char *description;
} bb_image_info;

typedef enum bb_addressing {
  BB_ADDRESS_PERIODIC = 0,
  BB_ADDRESS_CLAMP
} bb_addressing;

typedef enum bb_range {
  BB_RANGE_UNIT = 0,
  BB_RANGE_SIGNED
} bb_range;

typedef enum bb_channel {
  BB_CHANNEL_AUTO = 0,
  BB_CHANNEL_R,
  BB_CHANNEL_G,
  BB_CHANNEL_B,
  BB_CHANNEL_A,
  BB_CHANNEL_LUMA,
  BB_CHANNEL_MEAN
} bb_channel;

typedef struct bb_smooth_options {
  int radius_texels;
  float threshold;
  bb_addressing addressing;
} bb_smooth_options;

typedef enum bb_normal_filter {
  BB_NORMAL_VALVE = 0,
  BB_NORMAL_CENTRAL,
  BB_NORMAL_SOBEL,
  BB_NORMAL_VERTEX
} bb_normal_filter;

typedef struct bb_basis {
  int count;
  double vector[16][3];
  char name[32];
} bb_basis;

typedef int (*bb_progress_fn)(void *user, long done, long total);

typedef struct bb_region {
  int x0, y0, width, height;
} bb_region;

typedef struct bb_trace_options {
  double bias_texels;
  int threads;
  bb_region region;
  bb_progress_fn progress;
  void *progress_user;
} bb_trace_options;

typedef enum bb_output_kind {
  BB_OUTPUT_NORMAL = 0,
  BB_OUTPUT_WEIGHTS,
  BB_OUTPUT_SSBUMP,
  BB_OUTPUT_AO,
  BB_OUTPUT_BENT,
  BB_OUTPUT_FILTERED,
  BB_OUTPUT_KIND_COUNT
} bb_output_kind;

typedef struct bb_output_kind_info {
  const char *name;
  const char *description;
  int channels;
  bb_range range;
  int needs_trace;
} bb_output_kind_info;

typedef struct bb_bake_options {
  float height_scale;
  int rays;
  int slices;
  bb_smooth_options smooth;
  bb_trace_options trace;
  double power;
  bb_basis basis;
  bb_normal_filter normal_filter;
  int normal_y_up;
  unsigned outputs;
  double bounce_albedo;
  const bb_image *bounce_albedo_map;
  int bounces;
  const bb_image *brightness;
} bb_bake_options;

typedef struct bb_bake_result {
  bb_image filtered;
  bb_image normal;
  bb_image weights;
  bb_image vis;
  bb_image ssbump;
  bb_image ao;
  bb_image bent;
  double seconds_smooth, seconds_pyramid, seconds_trace, seconds_derive;
  double horizons_found;
  char rayset_id[64];
  bb_basis basis;
  int threads;
  int bounces;
  double seconds_bounce;
} bb_bake_result;
"""

# Functions, as declared in the header.
FUNCTIONS = """
const char *bb_status_name(bb_status status);
void bb_image_free(bb_image *img);
void bb_image_info_free(bb_image_info *info);
bb_status bb_image_read(const char *path, bb_image *out, bb_image_info *info,
                        bb_error *err);
bb_status bb_channel_parse(const char *name, bb_channel *out, bb_error *err);
bb_status bb_height_from_image(const bb_image *img, int alpha_channel,
                               bb_channel channel, bb_image *height,
                               bb_error *err);
bb_status bb_normal_filter_parse(const char *name, bb_normal_filter *out, bb_error *err);
const char *bb_normal_filter_name(bb_normal_filter f);
void bb_basis_init(bb_basis *b);
bb_status bb_basis_parse(const char *name, bb_basis *out, bb_error *err);
bb_status bb_basis_from_vectors(const double (*vectors)[3], int count, bb_basis *out,
                                bb_error *err);
bb_status bb_basis_load(const char *path, bb_basis *out, bb_error *err);
const bb_output_kind_info *bb_output_kind_get(bb_output_kind kind);
void bb_bake_options_init(bb_bake_options *o);
bb_status bb_bake_options_check(const bb_bake_options *o, bb_error *err);
bb_status bb_bake(const bb_image *height, const bb_bake_options *o,
                  bb_bake_result *result, bb_error *err);
const bb_image *bb_bake_result_image(const bb_bake_result *r, bb_output_kind kind);
void bb_bake_result_free(bb_bake_result *r);
bb_status bb_file_hash(const char *path, uint64_t *hash, bb_error *err);
"""

CDEF = TYPES + FUNCTIONS
