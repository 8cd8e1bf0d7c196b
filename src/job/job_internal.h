/* job_internal.h: what the job family's files share (not public): path
 * parts, depfile rules, and the planned job itself. */
#ifndef BB_JOB_INTERNAL_H
#define BB_JOB_INTERNAL_H

#include "bumpbake.h"
#include "core/file_names.h" /* bb__file_name, bb__file_extension */
#include "files/file_identity.h"
#include "job/job_options.h"
#include "mesh/mesh_internal.h" /* bb_renderbump_options */

#include <stddef.h>
#include <sys/types.h>

/* ------------------------------------------------------------ path parts */


/* normal2ssbump's output without -o, as Valve's tool names it (paths.c):
 * the input up to its first "_normal" (any case), else up to its first
 * '.', then "_ssbump.tga" (malloc'd; NULL when out of memory). */
char *bb__job_valve_weights_name(const char *input);


/* BB_OK when path's directory exists and is a directory and path itself is
 * nothing yet or a regular file (bb__safe_check_target); else BB_ERR_IO
 * "PATH: cannot write: ...". */
bb_status bb__check_output_directory(const char *path, bb_error *err);

/* path without the extension of its last component, plus suffix ("rock.png",
 * "-ssbump.tga" -> "rock-ssbump.tga"; a name's leading dot starts no
 * extension), malloc'd; NULL when out of memory. */
char *bb__path_with_suffix(const char *path, const char *suffix);

/* The file a bake with options o writes for map kind, the one rule for
 * it: o->paths[kind] when named, else -o PREFIX's "PREFIX_KIND.png" for
 * the kinds of BB_JOB_DEFAULT_MAPS, else none. *path is a malloc'd copy,
 * or NULL for none; BB_ERR_MEMORY when out of memory. */
bb_status bb__job_map_file(const bb_job_options *o, bb_map_kind kind, char **path, bb_error *err);

/* The file -o PREFIX (bb_job_options.prefix) names for kind:
 * "PREFIX_KIND.png" for the kinds of BB_JOB_DEFAULT_MAPS, malloc'd; NULL for
 * another kind, a NULL prefix or out of memory (bb__job_map_file's rule). */
char *bb__job_prefix_path(const char *prefix, bb_map_kind kind);

/* ------------------------------------------------------------ the bounce */

/* The rho a bake bounces with, the job's one rule for it: the rho asked,
 * or 1 when none is (0) and an albedo map is given (bake --bounce-albedo
 * FILE without --bounce: the map bounces as it is). bb__bake_checked itself ignores
 * a map while rho is 0, as bumpbake.h says. */
double bb__bounce_rho(double asked, int albedo_map);

/* --------------------------------------------------------------- depfiles */

/* One rule of a depfile: every target depends on every prerequisite. */
typedef struct bb__dep_rule {
  const char *const *targets;
  int target_count;
  const char *const *prerequisites;
  int prerequisite_count;
} bb__dep_rule;

/* BB_ERR_IO naming the first file name of the rules that a depfile
 * cannot hold (depfile.c says which characters), else BB_OK. */
bb_status bb__depfile_check_names(const char *depfile, const bb__dep_rule *rules, int count,
                                  bb_error *err);

/* The rules as depfile text (malloc'd, *size bytes), NULL when out of memory. */
char *bb__depfile_text(const bb__dep_rule *rules, int count, size_t *size);

/* ------------------------------------------------------------------- jobs */

/* One input of a job and its outputs (paths malloc'd for a batch, the
 * options' own for a single input). */
typedef struct bb__job_item {
  char *input;
  char *paths[BB_MAP_BAKED_COUNT]; /* NULL = kind not written */
  char *slope_lit_path;              /* single input with slope_lit */
  /* A single input's further files of its maps (one bake writes a map to
   * several files, each in its format): more_kinds[i]'s map to
   * more_paths[i], in the order given. */
  int more_count;
  int more_kinds[BB_JOB_MAX_OUTPUTS];
  char *more_paths[BB_JOB_MAX_OUTPUTS];
  /* The command each file of a map written to several files records (the
   * command less the map's other files, what a bake of that file alone
   * records); NULL: the job's command. */
  char *commands[BB_MAP_BAKED_COUNT];
  char *more_commands[BB_JOB_MAX_OUTPUTS];
  uint64_t file_hash;                /* the bytes checked for currency, 0 = not yet */
  bb_job_report report;
} bb__job_item;

struct bb_job {
  bb_job_options options;   /* as given; options.bake.outputs = the kinds asked */
  char *basis_file;         /* copies of the options' strings */
  char *out_dir, *name_template, *depfile, *command, *command_options;
  char *slope_path;
  char *bounce_albedo_file, *brightness_file;
  char *vmt, *vmt_materials, *vmt_basetexture;
  char *valve_path;         /* Valve's packed file (height2ssbump), or NULL */
  char *vmt_text;           /* the material's bytes, made by the plan */
  size_t vmt_size;
  bb_image bounce_albedo_map, brightness_map; /* read once by the plan */
  bb_bake_context *context; /* bb_job_use_context's, or NULL: cold bakes */
  bb__job_item *items;
  int count;
  int batch;                /* 1: out_dir names the outputs */
  char prerequisite_basis;  /* 1: basis_file is a prerequisite (a vectors basis) */
  const char *stage;        /* bb_job_stage: "bake", "compress" or NULL */
  char read_only;           /* 1: planned with BB__PLAN_READ_ONLY */
};

/* The most bytes reading, baking and writing item's input of w x h texels
 * and `channels` channels takes at one time (memory.c): an upper bound,
 * with 5% and 32 MiB to spare. */
double bb__job_memory(const bb_job *job, const bb__job_item *item, int w, int h,
                      int channels);

/* Before item's input is read: BB_ERR_MEMORY when reading, baking and
 * writing it would take more memory than is available (memory.c), naming
 * both figures; BB_OK otherwise, or when its header cannot be read. */
bb_status bb__job_memory_check(const bb_job *job, const bb__job_item *item, bb_error *err);

/* Most files one input's bake reads: the input, the basis file, the bounce
 * albedo map and the brightness map. */
#define BB__JOB_MAX_READS 4

/* The files item's bake reads, its depfile prerequisites, into out
 * (BB__JOB_MAX_READS entries); the count. */
int bb__job_reads(const bb_job *job, const bb__job_item *item, const char **out);

/* The settings a .vtf or .dds output of kind and range is written with:
 * given's (NULL: the defaults), the map set by bb__texture_options_for
 * (paths.c). */
bb_texture_options bb__job_texture_of(const bb_texture_options *given, const char *kind,
                                      bb_range range);

/* bb_outputs_write with the block compression of its engine textures
 * counted in watch (may be NULL): the job's compress stage, its progress
 * and seconds (texture/blocks.h). */
struct bb__blocks_watch;
bb_status bb__outputs_write(const bb_output_file *files, int count, int threads,
                            struct bb__blocks_watch *watch, bb_error *err);

/* Rows of 4 x 4 blocks the engine textures among files compress
 * (bb__texture_block_rows): a compress stage's total. */
long bb__outputs_block_rows(const bb_output_file *files, int count);

/* The maps o asks for: the named paths (and the filtered height the slope
 * map is made from, what Valve's file packs), or a batch's maps. The
 * commands' rules of what an option applies to read it too. */
unsigned bb__job_maps_asked(const bb_job_options *o);

/* The kind of Valve's packed file (bb_job_options.valve_path): "ssbump+height",
 * "normal+ao", "detail-ssbump+height"... */
const char *bb__job_valve_kind(const bb_job_options *o);

/* A single input's maps written to several files (a command's --MAP FILE
 * given more than once): count further files, kinds[i]'s map to paths[i],
 * and the command each records (commands[i]; first_commands[kind] for the
 * first file of a map, o->paths[kind]; NULL: the job's command). */
typedef struct bb__job_more {
  int count;
  const int *kinds;
  const char *const *paths;
  const char *const *commands;
  const char *first_commands[BB_MAP_BAKED_COUNT];
} bb__job_more;

/* Once in bumpbake.h, now internal (issue 41): no client of the library
 * plans a job of its own options since serve plans through its bake
 * command (bb_command_plan); the tests and the command's plan do. */

/* Plans a job over inputs[0..input_count-1]: files, and directories, which
 * give the image files in them (not below), sorted by name, leaving out
 * names starting with '.' and files whose provenance says bumpbake baked
 * them as maps (so a directory can be its own out_dir); a file named twice
 * counts once. o->command or o->command_options names the line its
 * outputs record (neither: BB_ERR_ARGUMENT). Every option and every output path is checked here, before
 * any bake (bb_outputs_check for each input's outputs against every input;
 * clashes across the whole batch; the depfile against every input and
 * output); out_dir and the template's subfolders, or a single input's
 * output folders (not the depfile's), are created. A directory as the one
 * input without out_dir is BB_ERR_ARGUMENT. Errors:
 * BB_ERR_ARGUMENT (a usage error: bad option, template or map name, a
 * clash, no output), BB_ERR_IO (an output over an input, a directory that
 * cannot be made or read), BB_ERR_MEMORY. On success *out receives the
 * job; free it with bb_job_free. */
bb_status bb__job_plan_options(const char *const *inputs, int input_count,
                               const bb_job_options *o, bb_job **out, bb_error *err);

/* bb__job_plan_options; flags: BB__PLAN_CHECKED: o's bake options were checked
 * already (a command's, cmd/plan.c) and are only resolved
 * (bb__bake_resolve); BB__PLAN_READ_ONLY: a plan whose outputs are read,
 * not written (a golden check): no directory is made, and none need exist;
 * more (may be NULL): the further files of a single input's maps. */
#define BB__PLAN_CHECKED 1u
#define BB__PLAN_READ_ONLY 2u
bb_status bb__job_plan(const char *const *inputs, int input_count, const bb_job_options *o,
                       unsigned flags, const bb__job_more *more, bb_job **out,
                       bb_error *err);

/* The map files of item in the order they are listed and written: each
 * map's first file (item->paths[kind]), then its further ones, by kind;
 * kinds, paths and commands (a file's own, NULL: the job's) hold
 * BB_JOB_MAX_OUTPUTS entries. The count. */
int bb__job_map_files(const bb__job_item *item, int *kinds, const char **paths,
                      const char **commands);

/* A batch's name template's fields {stem}, {kind} and {ext} ("{{" and "}}"
 * are braces) expanded with fields[0..2] into out (capacity cap): the name
 * of a map (plan.c), or with "*" for stem and extension the pattern of the
 * names a template can give a kind (a golden check's). */
bb_status bb__job_expand_name(const char *tmpl, const char *const fields[3], char *out,
                              size_t cap, bb_error *err);

/* bb_outputs_check; directories 0: leaves out the check of the outputs'
 * directories and of what their names hold now (paths.c). */
bb_status bb__outputs_check(const bb_output_spec *outputs, int count, const char *const *reads,
                            int read_count, int directories, bb_error *err);

/* What a golden check needs of a batch's maps (run.c), after input i was
 * baked by this job (bb_job_bake_item, its report filled): the depth map
 * kind is written with; the provenance text it records (malloc'd, NULL when
 * out of memory); and the maps of `maps` (BB_MAP_BIT(kind)s; 0: none)
 * written from result as bb_job_write_item writes them, all or nothing,
 * the other files of the input left as they are. */
bb_depth bb__job_map_depth(const bb_job *job, int i, int kind);
char *bb__job_map_description(const bb_job *job, int i, const bb_bake_result *result,
                              int kind);
bb_status bb__job_write_maps(bb_job *job, int i, const bb_bake_result *result, unsigned maps,
                             bb_error *err);

/* The provenance "command" of item i (malloc'd, NULL when out of memory). */
char *bb__job_command_of(const bb_job *job, const bb__job_item *item);

/* ------------------------------------------- one map or picture (output.c) */

/* Where an output came from, as its provenance records it
 * (bb__provenance_format). */
typedef struct bb__job_source {
  const char *command;          /* the command line the output records */
  const char *input;            /* the input's path (its file name is recorded), or NULL */
  const char *input_text;       /* else an input recorded as it is (a program's text) */
  uint64_t input_hash;          /* bb__image_hash of the input's pixels, 0: none */
  uint64_t input_file_hash;     /* bb_file_hash of its bytes, 0: unknown */
  const bb_bake_options *bake;  /* the bake's, when a height was baked */
  bb_channel channel;           /* the height's channel rule, when baked */
  const char *rayset_id;        /* when something was traced */
  const char *extra;            /* the output's own key=value lines, or NULL */
} bb__job_source;

/* The provenance of an output of kind made from s (its input recorded by
 * file name, or input_text as it is), and its text (malloc'd, NULL when out
 * of memory): every output's, a bake's maps' and what an up-to-date check
 * expects of them too. */
bb_provenance bb__job_provenance(const bb__job_source *s, const char *kind);
char *bb__job_describe(const bb__job_source *s, const char *kind);

/* The depth an output is written with: the one asked, else the input's
 * (bits_per_sample, is_float) where path's format holds it. */
bb_depth bb__job_depth(bb_depth asked, int bits_per_sample, int is_float, const char *path);

/* A file of a command that is not a bake: its map or picture, one of a
 * render bump's files, compare's diff. The command hands the job its
 * depth as data: the one asked, or the one its output is written with
 * where the format holds it (a render bump's 16-bit height, the diff's
 * float EXR). */
typedef struct bb__job_output {
  const char *path;
  const char *kind;              /* what it is, in messages and the written list */
  bb_range range;
  bb_depth depth;                /* asked, or the command's own */
  const bb_image_info *like;     /* the input a default depth follows, or NULL */
  int mips;                      /* a mip chain, where the format holds one */
  const bb_texture_options *texture; /* a .vtf's or .dds's settings, or NULL */
} bb__job_output;

/* o's path (or, frames > 0, every frame's: bb__render_frame_path; a .gif
 * path is one animation) checked before any work (bb_outputs_check): its
 * format, depth and mips, its directory, and that it is none of the
 * reads[0..read_count-1] under any spelling. */
bb_status bb__job_output_check(const bb__job_output *o, int frames, const char *const *reads,
                               int read_count, bb_error *err);

/* The outputs o[0..count-1] of one command (no frames), checked together
 * as bb__job_output_check checks one: each as above, and no two on one
 * file. */
bb_status bb__job_outputs_check(const bb__job_output *o, int count, const char *const *reads,
                                int read_count, bb_error *err);

/* One file of a set written together: where and how, its pixels, and
 * where they came from (NULL: no provenance is stored). */
typedef struct bb__job_file {
  const bb__job_output *output;
  const bb_image *image;
  const bb__job_source *source;
  const char *recorded_kind; /* the kind its provenance records; NULL: output->kind */
} bb__job_file;

/* files[0..count-1] written all or nothing (bb_outputs_write): each with
 * its depth and its provenance, staged, then put in place together (a
 * failure or an interruption leaves every old file). Errors: one file's
 * name its path once; a set's are bb_outputs_write's. */
bb_status bb__job_write_set(const bb__job_file *files, int count, bb_error *err);

/* bb__job_write_set of the one file o (img, with s's provenance). */
bb_status bb__job_write(const bb__job_output *o, const bb_image *img, const bb__job_source *s,
                        bb_error *err);

/* A picture, or the frames of an orbit, made one at a time: frame's
 * picture and its own provenance lines (*extra, malloc'd; extra is NULL
 * for a GIF, which stores none). */
typedef bb_status (*bb__job_frame_fn)(void *user, int frame, bb_image *picture, char **extra,
                                      bb_error *err);
typedef struct bb__job_frames {
  int frames;                    /* 0: one picture at o->path; else an orbit */
  const char *recorded_kind;     /* the kind the provenance records */
  const bb__job_source *source;
  bb__job_frame_fn make;
  void *user;
} bb__job_frames;

/* The picture, or an orbit's frames (bb__render_frame_path's names; a .gif
 * path: one animation), each staged as it is made, then all put in place
 * together or none. *written (malloc'd paths, *count of them) and *kind
 * ("orbit" for an animation, else o->kind) say what was written. */
bb_status bb__job_write_frames(const bb__job_output *o, const bb__job_frames *f, char ***written,
                               int *count, const char **kind, bb_error *err);

/* ------------------------------ a render bump's files, compare's diff */

/* A flat render bump's files as the job checks and writes them
 * (renderbump_files.c): out[0] the normal map at normal_path (RGB = N,
 * encoded 0.5 + 0.5 N in files that hold integers, range UNIT, else raw,
 * range SIGNED), out[1], when
 * height_path is not NULL, the height (range UNIT, 16-bit where the
 * format holds it). The count. */
int bb__renderbump_outputs(const char *normal_path, const char *height_path,
                           bb__job_output out[2]);

/* compare's |A - B| at path as the job checks and writes it
 * (compare_files.c): float in .exr (raw differences), the format's depth
 * elsewhere (scaled to a maximum of 1); no provenance. */
bb__job_output bb__compare_diff_output(const char *path);

/* Compares the image files a and b channel by channel under limits (NULL:
 * idiff's defaults; checked by bb__compare_limits_check before any read),
 * as OpenImageIO's idiff does, and their provenance key by key
 * (compare_files.c; compare's run). With diff_path (may be NULL; checked
 * by the command first), writes |A - B| there: raw in .exr, scaled
 * elsewhere so the largest finite difference is white (NaN and infinite
 * ones clip to 1). A diff that cannot be written does not change the
 * verdict: the report says so. Errors: those of bb_image_read for either
 * file (the message names it), BB_ERR_MEMORY. Free the report with
 * bb__compare_report_free. */
bb_status bb__compare_files(const char *a, const char *b, const bb_compare_limits *limits,
                            const char *diff_path, bb_compare_report *report, bb_error *err);

/* What bb__compare_files(a, b, ..., diff_path) will take, from the two
 * headers alone, before a pixel is read: the memory at its peak (A held
 * while B is read, then, with a diff, both, |A - B| and its encoder's
 * copy), refused when it will not fit (BB_ERR_MEMORY: "A: comparing two
 * 16384 x 16384 images of 4 channels needs about 12.6 GiB of memory; 2.4
 * GiB is available (RLIMIT_AS)"), and said through note (may be NULL),
 * naming a, when it is over BB_MAX_READ_BYTES ("comparing ... takes about
 * 12.6 GiB of memory (20.1 GiB is available)"). bb__compare_files makes
 * the same check first, without the note. Errors: the header reads'. */
bb_status bb__compare_files_check(const char *a, const char *b, const char *diff_path,
                                  bb_note_fn note, void *note_user, bb_error *err);

void bb__compare_report_free(bb_compare_report *report);

/* idiff's exit code for a report, which `bumpbake compare` exits with: the
 * verdict (0 pass, 1 warning, 2 failure), or BB_COMPARE_DIFFERENT_SIZE when
 * the sizes or channel counts differ. */
int bb__compare_report_exit_code(const bb_compare_report *report);

/* A comparison's statistics and the limits it was judged by, as members of
 * the JSON object j writes (compare --json, check --json, in one order):
 * pixels, mean_abs, rms, max_abs, worst {x, y, channel}, then idiff's
 * limits under its option names with the pixels over each threshold. */
struct bb__json;
void bb__compare_json(struct bb__json *j, const bb_compare_stats *s, const bb_compare_limits *l);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* 1 when a and b name the same file: the same device and inode when both
 * exist (symbolic and hard links, "./", ".."), else the same name in the
 * same directory (by the directory's device and inode), else the same
 * spelling. */
int bb__same_file(const char *a, const char *b);

/* Creates directory path and its missing parents (mode 0777 less the
 * umask), as mkdir -p. An existing directory is fine. Errors: BB_ERR_IO
 * ("PATH: cannot create directory: REASON"; a part that is a file). */
bb_status bb__directory_create(const char *path, bb_error *err);

/* Renames count staged files (bb__image_write_staged_all_cores, ...) into place in
 * order, as bb_outputs_write does with its set: the process's ending by a
 * signal waits for the last rename (bb_signal_cleanup). Every handle is
 * freed, committed or discarded: when a rename fails, the files after it
 * are discarded and the message says which were already replaced ("PATH:
 * reason; already written: KIND PATH, ..." with kinds[i], which may be
 * NULL). For sets too large to hold in memory at once, such as an
 * orbit's frames: stage each, then commit them together. */
bb_status bb__staged_files_commit(bb_staged_file **files, const char *const *kinds, int count,
                                 bb_error *err);

/* Writes a flat render bump's files together or neither (bb_outputs_write):
 * the normal map at normal_path (RGB = N as bumpbake stores normal maps:
 * 0.5 + 0.5 N in integer files, N in float ones; alpha = the coverage as it
 * is; green flipped for normal_y_up) and, when height_path is not NULL,
 * the height (16-bit where the format holds it). Each records provenance:
 * command, the model's file name and bb__mesh_hash (model_hash), its kind
 * ("normal+coverage", "height"), bb__renderbump_describe's keys and
 * normal_y. Errors as bb_outputs_write's. */
bb_status bb__renderbump_write(const bb_renderbump_result *r, const bb_renderbump_options *o,
                              int normal_y_up, const char *model, uint64_t model_hash,
                              const char *command, const char *normal_path,
                              const char *height_path, bb_error *err);

/* The depth nearest an input's (bits_per_sample, is_float) that path's
 * format holds, for outputs that are the height itself: 16 bits for a
 * 16-bit input, float or half for a float or half input; BB_DEPTH_DEFAULT
 * for an 8-bit input or when the format holds nothing deeper (TGA). */
bb_depth bb__depth_like_input(int bits_per_sample, int is_float, const char *path);

/* The rayset id bb__bake_checked records in result->rayset_id for options o (slices
 * from o->slices, or from o->rays; power; basis), computed without building
 * the rayset, into out (capacity cap, NUL-terminated, cut to fit; 64 holds
 * any id). "" when o->outputs asks for no traced kind: nothing is traced
 * then, and provenance says rayset=none. */
void bb__bake_rayset_id(const bb_bake_options *o, char *out, size_t cap);


/* Decides from the header of the file at path alone (bb_image_read_info;
 * no pixel is decoded) whether it is what writing the output described by
 * expected, at sample depth `depth` and mip-mapped or not (mip_mapped 0 or
 * 1), would make now. CURRENT when its provenance is bumpbake's, intact
 * (bb_provenance_class), and holds every key bb__provenance_format(expected)
 * writes with the same value, and no key that text lacks, except "command"
 * and "input" (the command line and the input's name, which do not change a
 * pixel) and "input_hash" (the decoded height's hash, implied by
 * input_file_hash and channel), and keys the file's kind does not record
 * (bb__map_kind_records: a normal map written before the rule, with "rays",
 * is current): so the bumpbake version, the input file's bytes, the output
 * kind and every parameter that affects its pixels must match; and when its samples have the depth `depth` gives in path's format
 * (BB_DEPTH_DEFAULT: the format's default) and it has more than one mip
 * level exactly when mip_mapped. expected->input_file_hash must be set
 * (nonzero): without it nothing is CURRENT. A file that cannot be read is
 * STALE, not an error: rewriting it is the remedy. reason (capacity cap;
 * may be NULL) receives why it is not CURRENT, one line ("no such file",
 * "scale: 8 -> 16", "bumpbake_version: 0.1.0 -> 0.2.0", "16-bit samples;
 * 8-bit asked"), or "" when it is. Returns BB_OK with *state set, or
 * BB_ERR_ARGUMENT (NULL path, expected or state; depth out of range) or
 * BB_ERR_MEMORY. */
bb_status bb__output_check(const char *path, const bb_provenance *expected, bb_depth depth,
                          int mip_mapped, bb_output_state *state, char *reason, size_t cap,
                          bb_error *err);

/* The words of bb_report_word's fields: "pending", ..., "not run" and
 * "PASS", ..., "EXTRA"; "unknown" outside the enum. */
const char *bb__job_outcome_name(bb_job_outcome outcome);
const char *bb__check_status_name(bb_check_status status);

/* Once in bumpbake.h, now internal (issue 41): no client of the library
 * calls it; the library, tests and tools do. */
/* Reads the height of the file at path by the channel rule
 * (bb_channel): the file's bytes are hashed first, then decoded, so
 * provenance never pairs a newer file's hash with older pixels. note (may
 * be NULL) hears which channel the rule took when it was not the obvious
 * one, and warnings about the input (lossy JPEG blocks, 8-bit codes that
 * terrace at the scale asked). height_scale (0: not known) is the bake's,
 * for the terracing note. source may be NULL. Errors as bb_image_read and
 * bb_height_from_image, each naming path. */
bb_status bb__height_file_read(const char *path, bb_channel channel, float height_scale,
                              bb_note_fn note, void *note_user, bb_image *height,
                              bb_height_source *source, bb_error *err);

/* Once in bumpbake.h, now internal (issue 41): no client of the library
 * calls it; the library, tests and tools do. */
/* Formats p as "key=value" lines (bumpbake_version, command, input, input_hash,
 * input_file_hash when known, output, scale, rays, rayset, filter_radius,
 * filter_threshold, bias, power, basis, normal_filter, normal_y, addressing,
 * channel), malloc'd; the caller
 * frees it. With options (a bake's map), only the parameters output_kind
 * records are written (a normal map has no rays,
 * rayset, bias, power or basis; ao's rayset is its scheme and slices);
 * without, rayset is written as given ("none" when NULL). A basis of the caller's vectors ("vectors:HASH") adds
 * basis_vectors after basis: "x y z" per direction, joined by "; ".
 * Options in use add, after addressing: bounce (rho) and bounces when
 * bounce_albedo > 0, with bounce_albedo_map (the hash of the map's pixels, 16
 * hex digits) when it has one; brightness (the hash of the
 * brightness map's pixels) when there is one.
 * Returns NULL when out of memory. */
char *bb__provenance_format(const bb_provenance *p);

#endif /* BB_JOB_INTERNAL_H */
