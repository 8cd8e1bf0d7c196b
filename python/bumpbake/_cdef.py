"""The part of include/bumpbake.h and bumpbake_cluster.h the Python package
calls, for cffi.

Every type and function the package uses, and nothing else but
bb_command_info_get, with which its tests walk the commands
(tests/test_commands.py). The structs must
match the header field for field, since cffi's ABI mode lays them out from
these declarations: tests/test_cdef.py compiles a C program against the real
header and checks every size, offset, enum value and function signature
declared here, so a change to the header fails that test, naming what to
update. Declarations are the header's as they are, in its order, comments
dropped and array sizes and constants written as numbers (BB_MAX_BASIS 16,
BB_MAP_BAKED_COUNT 6, BB_MAP_KIND_COUNT 8, BB_JOB_MAX_OUTPUTS 10; the VTF flags in decimal), which
cffi needs; the test checks those numbers too.
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


typedef int (*bb_progress_fn)(void *user, long done, long total);

typedef void (*bb_note_fn)(void *user, const char *path, const char *text);

typedef struct bb_region {
  int x0, y0, width, height;
} bb_region;

typedef struct bb_image_info {
  int alpha_channel;
  int is_float;
  int bits_per_sample;
  char format_name[32];
  char *description;
} bb_image_info;

typedef enum bb_depth {
  BB_DEPTH_DEFAULT = 0,
  BB_DEPTH_8,
  BB_DEPTH_16,
  BB_DEPTH_HALF,
  BB_DEPTH_FLOAT
} bb_depth;

typedef enum bb_range {
  BB_RANGE_UNIT = 0,
  BB_RANGE_SIGNED
} bb_range;

typedef enum bb_map_kind {
  BB_MAP_NORMAL = 0,
  BB_MAP_WEIGHTS,
  BB_MAP_SSBUMP,
  BB_MAP_AO,
  BB_MAP_BENT,
  BB_MAP_FILTERED,
  BB_MAP_SLOPE,
  BB_MAP_PLAIN,
  BB_MAP_KIND_COUNT
} bb_map_kind;

typedef struct bb_map_kind_info {
  const char *name;
  const char *description;
  int channels;
  int file_channels;
  bb_range range;
  int needs_trace;
  int unit_vectors;
  uint32_t vtf_flags;
} bb_map_kind_info;

typedef enum bb_texture_format {
  BB_TEXTURE_FORMAT_DEFAULT = 0,
  BB_TEXTURE_FORMAT_BC1,
  BB_TEXTURE_FORMAT_BC3,
  BB_TEXTURE_FORMAT_BC4,
  BB_TEXTURE_FORMAT_BC5,
  BB_TEXTURE_FORMAT_BGR8,
  BB_TEXTURE_FORMAT_BGRA8,
  BB_TEXTURE_FORMAT_RGBA8,
  BB_TEXTURE_FORMAT_RGBA16F,
  BB_TEXTURE_FORMAT_RGBA32F
} bb_texture_format;

typedef struct bb_texture_options {
  bb_texture_format format;
  bb_map_kind map;
  int mips;
  int fast;
  int threads;
  int vtf_version;
  uint32_t vtf_flags;
  const char *description;
} bb_texture_options;

typedef struct bb_vtf_info {
  int version_major, version_minor;
  int header_size;
  int width, height, depth;
  int frames, first_frame;
  uint32_t flags;
  float reflectivity[3];
  float bump_scale;
  int format;
  char format_name[24];
  int mip_count;
  int low_res_format;
  int low_res_width, low_res_height;
  int resource_count;
  long data_size;
  char *description;
} bb_vtf_info;

typedef struct bb_dds_info {
  int width, height;
  int mip_count;
  char fourcc[5];
  int dxgi_format;
  char format_name[32];
  char compression[8];
  uint32_t pixel_flags;
  uint32_t caps2;
} bb_dds_info;

typedef struct bb_vmt_options {
  const char *materials_dir;
  const char *bumpmap;
  const char *basetexture;
  int ssbump;
} bb_vmt_options;

typedef enum bb_channel {
  BB_CHANNEL_AUTO = 0,
  BB_CHANNEL_R,
  BB_CHANNEL_G,
  BB_CHANNEL_B,
  BB_CHANNEL_A,
  BB_CHANNEL_LUMA,
  BB_CHANNEL_MEAN,
  BB_CHANNEL_VALVE
} bb_channel;



typedef struct bb_basis {
  int count;
  double vector[16][3];
  char name[32];
} bb_basis;

typedef struct bb_pyramid bb_pyramid;

typedef struct bb_rayset bb_rayset;

typedef struct bb_trace_options bb_trace_options;

typedef bb_status (*bb_trace_fn)(void *user, const bb_pyramid *p, const bb_rayset *rs,
                                 const bb_trace_options *o, bb_image *vis, bb_error *err);

struct bb_trace_options {
  double bias_texels;
  int threads;
  bb_region region;
  bb_progress_fn progress;
  void *progress_user;
  bb_trace_fn trace;
  void *trace_user;
};


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

typedef struct bb_bake_context bb_bake_context;


typedef enum bb_mip_filter {
  BB_MIP_AVERAGE = 0,
  BB_MIP_RENORMALIZE
} bb_mip_filter;

typedef struct bb_compare_stats {
  double mean_abs, rms, max_abs;
  int worst_x, worst_y, worst_channel;
  long pixels;
  long over_fail, over_warn;
} bb_compare_stats;

typedef struct bb_compare_limits {
  double fail;
  double fail_percent;
  double hard_fail;
  long allow_failures;
  double warn;
  double warn_percent;
  double hard_warn;
} bb_compare_limits;

typedef enum bb_compare_verdict {
  BB_COMPARE_PASS = 0,
  BB_COMPARE_WARN = 1,
  BB_COMPARE_FAIL = 2
} bb_compare_verdict;

typedef struct bb_render_maps {
  const bb_image *normal;
  const bb_image *ssbump;
  const bb_image *ao;
  const bb_image *bent;
  const bb_image *albedo;
  const bb_image *slope;
} bb_render_maps;

typedef struct bb_renderbump_result {
  bb_image normal;
  bb_image height;
  double rect[4];
  double depth_min, depth_max;
  double texel_size;
  double texel_aspect;
  double height_scale;
  int used_vertex_normals;
  size_t triangles_drawn;
  size_t triangles, vertices;
  uint64_t model_hash;
} bb_renderbump_result;

typedef enum bb_provenance_class {
  BB_PROVENANCE_NONE = 0,
  BB_PROVENANCE_INTACT,
  BB_PROVENANCE_DAMAGED
} bb_provenance_class;

typedef struct bb_provenance_entry {
  const char *key;
  size_t key_length;
  const char *value;
  size_t value_length;
} bb_provenance_entry;

typedef struct bb_output_spec {
  const char *path;
  const char *kind;
  int channels;
  bb_depth depth;
  int mips;
  int text;
  int width, height;
  bb_range range;
  const bb_texture_options *texture;
} bb_output_spec;

typedef struct bb_output_file {
  const char *path;
  const char *kind;
  const bb_image *image;
  bb_range range;
  bb_depth depth;
  int mips;
  const char *description;
  const void *text;
  size_t text_size;
  const bb_texture_options *texture;
} bb_output_file;

typedef struct bb_height_source {
  bb_channel channel;
  int grey;
  int channels;
  int bits_per_sample;
  int is_float;
  char format_name[32];
  uint64_t file_hash;
  uint64_t height_hash;
} bb_height_source;

typedef struct bb_compare_report {
  int same_shape;
  int width, height, channels;
  int b_width, b_height, b_channels;
  bb_compare_stats stats;
  bb_compare_verdict verdict;
  bb_provenance_class provenance_a, provenance_b;
  int provenance_differences;
  char *provenance_diff;
  int diff_written;
  bb_error diff_error;
  const char *result;
} bb_compare_report;

typedef enum bb_check_status {
  BB_CHECK_PASS = 0,
  BB_CHECK_WARNING,
  BB_CHECK_FAILURE,
  BB_CHECK_DIFFERENT_SIZE,
  BB_CHECK_UNREADABLE,
  BB_CHECK_MISSING,
  BB_CHECK_EXTRA
} bb_check_status;

typedef struct bb_check_case {
  const char *name;
  const char *golden;
  const char *fresh;
  const char *kind;
  bb_check_status status;
  int exit_code;
  bb_compare_limits limits;
  int width, height, channels;
  int new_width, new_height, new_channels;
  bb_compare_stats stats;
  const char *provenance_diff;
  const char *message;
  int updated;
  const char *update_error;
  double seconds;
} bb_check_case;

typedef struct bb_check bb_check;
typedef void (*bb_check_case_fn)(void *user, const bb_check_case *c);


typedef struct bb_job bb_job;

typedef enum bb_job_outcome {
  BB_JOB_PENDING = 0,
  BB_JOB_BAKED,
  BB_JOB_CURRENT,
  BB_JOB_FAILED,
  BB_JOB_NOT_RUN
} bb_job_outcome;

typedef struct bb_job_file {
  const char *kind;
  const char *path;
} bb_job_file;

typedef struct bb_job_report {
  const char *input;
  int output_count;
  bb_job_file outputs[10];
  bb_job_outcome outcome;
  bb_status status;
  bb_error error;
  char reason[256];
  int width, height;
  bb_height_source source;
  int threads;
  int slices;
  char rayset_id[64];
  double horizons;
  double seconds_load, seconds_smooth, seconds_pyramid, seconds_trace,
      seconds_derive, seconds_write;
  int bounces;
  double seconds_bounce;
  double seconds_compress;
} bb_job_report;

typedef enum bb_option_type {
  BB_OPTION_FLAG = 0,
  BB_OPTION_INT,
  BB_OPTION_NUMBER,
  BB_OPTION_WORD,
  BB_OPTION_WORDS,
  BB_OPTION_NUMBERS,
  BB_OPTION_TEXT,
  BB_OPTION_PATH
} bb_option_type;

typedef enum bb_spelling {
  BB_SPELLING_COMMAND_LINE = 0,
  BB_SPELLING_KEYWORDS
} bb_spelling;
typedef enum bb_option_mode {
  BB_MODE_ANY = 0,
  BB_MODE_SINGLE,
  BB_MODE_BATCH
} bb_option_mode;

typedef struct bb_option_info {
  const char *name;
  char short_name;
  const char *value_name;
  bb_option_type type;
  int count;
  int values;
  bb_option_mode mode;
  unsigned flags;
  const char *help;
  const char *default_text;
  const char *range_text;
  const char *applies;
} bb_option_info;

typedef struct bb_command_info {
  const char *name;
  const char *summary;
  const char *synopsis;
  const char *description;
  const char *inputs;
  int min_inputs, max_inputs;
  int usage_exit;
  int option_count;
} bb_command_info;

typedef struct bb_command bb_command;

typedef struct bb_command_hooks {
  bb_note_fn note;
  void *note_user;
  bb_progress_fn progress;
  void *progress_user;
  bb_trace_fn trace;
  void *trace_user;
} bb_command_hooks;

typedef struct bb_info_file {
  const char *path;
  bb_status status;
  const char *error;
  int width, height, channels;
  bb_image_info image;
  bb_provenance_class provenance;
  int provenance_count;
  const bb_provenance_entry *provenance_entries;
  const bb_vtf_info *vtf;
  const bb_dds_info *dds;
  const char *flag_names[32];
} bb_info_file;

typedef struct bb_command_print {
  int error;
  const char *path;
  char *text;
} bb_command_print;

typedef struct bb_command_result {
  int file_count;
  bb_job_file *files;
  int frames;
  int labels_drawn;
  int exit_code;
  const bb_compare_report *compare;
  int info_count;
  const bb_info_file *info;
  int print_count;
  const bb_command_print *prints;
} bb_command_result;
"""

# Functions, in header order.
FUNCTIONS = """
const char *bb_status_name(bb_status status);
bb_status bb_image_size_check(int width, int height, int channels, bb_error *err);
bb_status bb_image_alloc(bb_image *img, int width, int height, int channels,
                         bb_error *err);
void bb_image_free(bb_image *img);
void bb_image_info_free(bb_image_info *info);
bb_status bb_image_read(const char *path, bb_image *out, bb_image_info *info,
                        bb_error *err);
const bb_map_kind_info *bb_map_kind_get(bb_map_kind kind);
void bb_texture_options_init(bb_texture_options *options);
bb_status bb_vmt_write(const char *path, const bb_vmt_options *options, bb_error *err);
bb_status bb_tempfiles_sweep(const char *dir, int *removed, bb_error *err);
bb_status bb_height_from_image(const bb_image *img, int alpha_channel,
                               bb_channel channel, bb_image *height,
                               bb_error *err);
bb_status bb_normal_map_decode(const bb_image *values, int is_float, int normal_y_up,
                               int normalize, bb_image *normals, bb_error *err);
bb_status bb_basis_from_vectors(const double (*vectors)[3], int count, bb_basis *out,
                                bb_error *err);
bb_status bb_basis_resolve(const char *spec, bb_basis *out, int *from_file, bb_error *err);
void bb_pyramid_free(bb_pyramid *p);
void bb_rayset_free(bb_rayset *rs);
int bb_rayset_slice_count(const bb_rayset *rs);
int bb_rayset_lobe_count(const bb_rayset *rs);
const char *bb_rayset_id(const bb_rayset *rs);
bb_status bb_trace_slice_order(const bb_rayset *rs, int *order, bb_error *err);
bb_status bb_trace_horizons(const bb_pyramid *p, const bb_rayset *rs,
                            const bb_trace_options *o, const int *slices, int count,
                            bb_image *horizons, bb_error *err);
bb_status bb_trace_accumulate(const bb_rayset *rs, int rank, const bb_image *horizon,
                              bb_image *sums, int threads, bb_error *err);
bb_status bb_trace_finish(const bb_rayset *rs, bb_image *sums, int threads, bb_error *err);
bb_status bb_bake_context_new(bb_bake_context **out, bb_error *err);
void bb_bake_context_free(bb_bake_context *context);
void bb_bake_context_keep(bb_bake_context *context, int keep);
bb_status bb_mip_chain(const bb_image *img, bb_mip_filter filter, bb_image **levels,
                       int *count, bb_error *err);
void bb_mip_chain_free(bb_image *levels, int count);
bb_status bb_render_map_read(const char *path, bb_map_kind kind, int normal_y_up,
                             const bb_image *like, bb_image *out, uint64_t *hash,
                             bb_error *err);
void bb_renderbump_result_free(bb_renderbump_result *r);
bb_status bb_outputs_check(const bb_output_spec *outputs, int count,
                           const char *const *reads, int read_count, bb_error *err);
bb_status bb_outputs_write(const bb_output_file *files, int count, int threads, bb_error *err);
const char *bb_height_source_channel(const bb_height_source *source);
void bb_check_free(bb_check *check);
int bb_check_input_count(const bb_check *check);
const char *bb_check_input(const bb_check *check, int i);
bb_status bb_check_run_input(bb_check *check, int i, bb_progress_fn progress,
                             void *progress_user, bb_check_case_fn each, void *user,
                             bb_error *err);
bb_status bb_check_run_rest(bb_check *check, bb_check_case_fn each, void *user,
                            bb_error *err);
int bb_check_case_count(const bb_check *check);
const bb_check_case *bb_check_case_get(const bb_check *check, int i);
int bb_check_exit_code(const bb_check *check);
char *bb_check_case_lines(const bb_check *check, const bb_check_case *c);
char *bb_check_summary_lines(const bb_check *check);
bb_status bb_check_write_reports(bb_check *check, bb_error *err);
char *bb_check_export(bb_check *check, int first, size_t *size);
bb_status bb_check_import(bb_check *check, const char *data, size_t size, bb_error *err);
void bb_job_free(bb_job *job);
int bb_job_count(const bb_job *job);
const bb_job_report *bb_job_report_get(const bb_job *job, int i);
bb_status bb_job_check_current(bb_job *job, int i, int *current, bb_error *err);
bb_status bb_job_run_item(bb_job *job, int i, bb_progress_fn progress, void *progress_user);
bb_status bb_job_write_depfile(bb_job *job, bb_error *err);
bb_status bb_file_hash(const char *path, uint64_t *hash, bb_error *err);
const bb_command_info *bb_command_info_get(int index);
const bb_command_info *bb_command_info_find(const char *name);
const bb_option_info *bb_command_option(const bb_command_info *command, int index);
const char *bb_option_type_name(bb_option_type type);
const bb_option_info *bb_option_find(const bb_command_info *command, const char *name,
                                     size_t length);
const bb_option_info *bb_option_nearest(const bb_command_info *command, const char *name,
                                        size_t length);
void bb_option_range_text(const bb_option_info *option, char *out, size_t cap);
void bb_option_value_text(const bb_option_info *option, char *out, size_t cap);
void bb_option_default_text(const bb_command_info *command, const bb_option_info *option,
                            char *out, size_t cap);
bb_status bb_option_parse(const bb_option_info *option, const char *text, long long *value,
                          bb_error *err);
bb_status bb_command_new(const char *name, bb_command **out, bb_error *err);
void bb_command_free(bb_command *command);
const bb_command_info *bb_command_describe(const bb_command *command);
bb_status bb_command_set_basis(bb_command *command, const bb_basis *basis, bb_error *err);
bb_status bb_command_set(bb_command *command, const char *name, const char *text,
                         bb_error *err);
bb_status bb_command_add_input(bb_command *command, const char *text, bb_error *err);
bb_status bb_command_check(bb_command *command, bb_error *err);
void bb_command_set_in_memory(bb_command *command, unsigned maps);
void bb_command_set_spelling(bb_command *command, bb_spelling spelling);
int bb_command_given(const bb_command *command, const char *name);
bb_status bb_command_value(const bb_command *command, const char *name, char *out,
                           size_t cap, bb_error *err);
bb_status bb_command_numbers(const bb_command *command, const char *name, double *values,
                             int cap, int *count, bb_error *err);
void bb_command_set_picture(bb_command *command, int dynamic_light, int tile_y);
char *bb_command_text(const bb_command *command, const char *input, unsigned flags);
char *bb_command_handover(const bb_command *command, size_t *size);
bb_status bb_command_from_handover(const char *data, size_t size, const char *const *inputs,
                                   int input_count, bb_command **out, bb_error *err);
bb_status bb_command_trace_input(const bb_command *command, int threads, uint64_t file_hash,
                                 bb_pyramid **pyramid, bb_rayset **rays, bb_error *err);
bb_status bb_command_set_record(bb_command *command, const char *path, const char *line,
                                const char *options, bb_error *err);
bb_status bb_command_plan(bb_command *command, const bb_command_hooks *hooks, bb_job **job,
                          bb_error *err);
bb_status bb_command_run(bb_command *command, const bb_command_hooks *hooks,
                         bb_command_result *result, bb_error *err);
void bb_command_result_free(bb_command_result *result);
bb_status bb_command_renderbump(bb_command *command, const bb_command_hooks *hooks,
                                bb_renderbump_result *render, bb_command_result *result,
                                bb_error *err);
bb_status bb_command_picture(bb_command *command, const bb_image *height,
                             const bb_render_maps *maps, const bb_command_hooks *hooks,
                             bb_image *out, int *labels_drawn, bb_error *err);
bb_status bb_command_program(bb_command *command, bb_image *out, int *is_normal_map,
                             bb_error *err);
bb_status bb_command_map(bb_command *command, const bb_image *a, const bb_image *b,
                         const bb_image *mask, bb_depth b_depth, const bb_basis *basis,
                         bb_image *out, bb_error *err);
bb_status bb_command_bake(bb_command *command, const bb_image *height,
                          const bb_image *bounce_albedo, const bb_image *brightness,
                          const bb_basis *basis, const bb_command_hooks *hooks,
                          bb_bake_context *context, bb_image *maps, bb_region *changed,
                          bb_error *err);
const char *bb_report_word(const char *field, int value);
bb_status bb_check_plan(bb_command *command, const bb_command_hooks *hooks, bb_check **out,
                        bb_error *err);
/* what a job prints (bumpbake bake --scheduler) */
char *bb_job_report_lines(const bb_command *command, const bb_job_report *r, int batch,
                          const char *extra_json);
char *bb_job_summary_lines(const bb_command *command, const int *counts, int files);
"""

# Constants of the header (#define), by value: cffi reads only literals.
CONSTANTS = """
#define BB_MAX_THREADS 4096
#define BB_MAX_RAYS 65536
#define BB_MAX_SLICES 256
#define BB_MAX_BASIS 16
#define BB_MAP_BAKED_COUNT 6
#define BB_MAPS_BAKED 63
#define BB_COMPARE_DIFFERENT_SIZE 3
#define BB_COMPARE_CANNOT_READ 4
#define BB_JOB_MAX_OUTPUTS 10
#define BB_JOB_DEFAULT_MAPS 13
#define BB_VTF_FLAG_EIGHTBITALPHA 8192
#define BB_VTF_FLAG_NORMAL 128
#define BB_VTF_FLAG_NOMIP 256
#define BB_VTF_FLAG_NOLOD 512
#define BB_VTF_FLAG_ENVMAP 16384
#define BB_VTF_FLAG_SSBUMP 134217728
#define BB_OPTION_RECORDED 1
#define BB_OPTION_CLIENT 2
#define BB_OPTION_SINGLE_DASH 4
#define BB_OPTION_REQUIRED 8
#define BB_OPTION_FILES 16
"""

# From the C library: the strings the library returns malloc'd
# (bb_command_text) are freed with it.
LIBC = """
void free(void *ptr);
"""

CDEF = CONSTANTS + TYPES + FUNCTIONS + LIBC
