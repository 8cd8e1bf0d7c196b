/* bumpbake_cluster.h: the advanced calls of bumpbake, for drivers that
 * spread its work over processes or machines (Python's bumpbake.dask,
 * `bumpbake bake --scheduler`, `bumpbake serve`): a trace split into
 * slices and added up in one order, a checked command handed over as
 * text, the command line's report lines, and the sweep of the
 * temporaries a killed writer left. A program that bakes, renders or
 * runs commands needs only bumpbake.h; this header includes it, and the
 * library exports both (one soname, one ABI: make check-abi reads both).
 * docs/cluster.md tells how the pieces fit. */
#ifndef BUMPBAKE_CLUSTER_H
#define BUMPBAKE_CLUSTER_H

#include "bumpbake.h"

#ifdef __cplusplus
extern "C" {
#endif

/* --------------------------------------- files: orphaned temporaries */

/* Removes from directory dir (not below it) the temporaries
 * ".bb-tmp-XXXXXX.EXT" whose writer is gone, and the private directories
 * ".bb-tmp-XXXXXX" some encoders write in with what they hold: a writer
 * holds an advisory lock (flock) on its temporary from its creation until
 * it is renamed into place or removed, and the kernel drops it when the
 * process dies, so one that no process holds is what a process killed
 * outright (SIGKILL, an out-of-memory kill, a lost machine) left behind.
 * Temporaries being written, by this process or any other, on this machine
 * or another sharing the directory (NFS v4 carries flock), are left alone,
 * and so is a private directory holding anything but its staged file. *removed (may be
 * NULL) receives how many were removed. Errors: BB_ERR_ARGUMENT (no dir),
 * BB_ERR_IO (dir cannot be read, an orphan cannot be removed). */
bb_status bb_tempfiles_sweep(const char *dir, int *removed, bb_error *err);

/* -------------------------------- trace: a trace split over machines */

/* A trace split over processes or machines (Python's bumpbake.dask bakes
 * big maps so): each finds the horizons of some of the slices
 * (bb_trace_horizons), and one adds them up (bb_trace_accumulate) in the
 * order every trace adds them (bb_trace_slice_order) and turns the sums into
 * visibilities (bb_trace_finish). The result is a bake's trace's, bit
 * for bit: the same horizons, the same losses, added in the same order. */

/* The order in which every trace adds its slices' losses to a texel's sums:
 * order[k] is the slice added k-th (k is its rank), for k = 0 ..
 * bb_rayset_slice_count(rs) - 1; each slice is followed by its opposite
 * (lattice step (-a, -b)) when the set has one. Errors: BB_ERR_ARGUMENT,
 * BB_ERR_MEMORY. */
bb_status bb_trace_slice_order(const bb_rayset *rs, int *order, bb_error *err);

/* The horizon of every texel in count distinct slices of rs, found by the
 * line sweeps a bake's trace runs: horizons[k] (allocated here: 1
 * channel, the pyramid's size) holds slice slices[k]'s horizons, tangents of
 * elevation >= 0 (rise per texel of horizontal distance; 0 where nothing
 * rises above the origin), the floats the whole trace adds up. A slice and
 * its opposite asked together share one sweep, as they do in the whole
 * trace. o->region must be empty (the whole pyramid); o->bias_texels,
 * o->threads and o->progress (once per sweep) as for a bake's trace.
 * Memory: 4 bytes per texel per slice, plus a line's profile per thread.
 * Errors: BB_ERR_ARGUMENT (a slice out of range or asked twice, a region),
 * BB_ERR_MEMORY, BB_ERR_CANCELLED; then no image is left allocated. */
bb_status bb_trace_horizons(const bb_pyramid *p, const bb_rayset *rs,
                            const bb_trace_options *o, const int *slices, int count,
                            bb_image *horizons, bb_error *err);

/* Adds what slice order[rank] (bb_trace_slice_order) loses at each texel's
 * horizon (horizon: that slice's image from bb_trace_horizons) to sums:
 * 1 + bb_rayset_lobe_count(rs) channels (ao first, then each lobe), the
 * horizons' size, all zeros before rank 0 (bb_image_alloc makes them so).
 * Called for ranks 0, 1, ..., slice count - 1 in turn, each once, it adds
 * what a bake's trace adds in the order it adds it, so the sums are the
 * same bits; the caller keeps to that order. threads: 0 = all cores (the
 * same bits for any). Errors: BB_ERR_ARGUMENT (rank out of range, sizes or
 * channels that do not match). */
bb_status bb_trace_accumulate(const bb_rayset *rs, int rank, const bb_image *horizon,
                              bb_image *sums, int threads, bb_error *err);

/* Turns sums, once every rank is added, into visibilities in place: ao,
 * vis_0, vis_1, ... in [0, 1], 1 - lost / total, as a bake's trace
 * makes them. Errors: BB_ERR_ARGUMENT (channels other than 1 + lobes). */
bb_status bb_trace_finish(const bb_rayset *rs, bb_image *sums, int threads, bb_error *err);

/* -------------------------------- cmd: a checked command handed over */

/* The hand-over of a checked command to another process (bake
 * --scheduler hands its command to Python's bumpbake.dask): its inputs,
 * every option given with the text it was set from, and its record, as
 * bytes (NUL-separated fields, *size of them). malloc'd; NULL when out of
 * memory. */
char *bb_command_handover(const bb_command *command, size_t *size);

/* The command of a hand-over, set again through bb_command_set,
 * bb_command_add_input and bb_command_set_record and checked
 * (bb_command_check): the same options, parsed by the same functions.
 * inputs not NULL: those input_count inputs in place of the hand-over's (a
 * part of a batch, planned on a worker). Free with bb_command_free.
 * Errors: BB_ERR_ARGUMENT (not a hand-over of this version, or what
 * bb_command_check refuses), BB_ERR_MEMORY. */
bb_status bb_command_from_handover(const char *data, size_t size, const char *const *inputs,
                                   int input_count, bb_command **out, bb_error *err);

/* ------------------------------ cmd: the command line's report lines */

/* The lines `bumpbake bake` (bake, normal, height2ssbump) prints on stdout
 * of one input's report r, as command's --json and --quiet ask, the command
 * line's and its --scheduler run's alike: "wrote KIND PATH" or "up to date
 * KIND PATH" per file (control characters escaped, bb_text_printable), or
 * with json the input's JSON line (bb_command_report_json's; with batch a
 * "status" and, for an input not baked, the short line: input, status,
 * exit_code when it failed, every output). Nothing for an input not run,
 * nor for a failure without json (its error is the caller's line on
 * stderr). extra_json (may be NULL): members written before "outputs" of a
 * baked input's line ("\"cluster\":{...}"). Returns the text, "" when none,
 * to free(); NULL when out of memory. */
char *bb_job_report_lines(const bb_command *command, const bb_job_report *r, int batch,
                          const char *extra_json);
/* A batch's summary line of command over files inputs, with counts[k] the
 * inputs whose outcome is k (a bb_job_outcome, 5 of them): "NAME: N files:
 * B baked, C up to date, F failed[, R not run (...)]", or its JSON line
 * with --json; "" with --quiet. To free(); NULL when out of memory. */
char *bb_job_summary_lines(const bb_command *command, const int *counts, int files);

/* ------------------------- cmd: what a handed-over command's bake traces */

/* What a split trace's worker traces of a checked command's bake (bake or
 * height2ssbump, one input file; a hand-over, bb_command_from_handover):
 * the input height read as the bake reads it (the channel rule, with
 * the command's --channel and --scale), which must be the bytes the bake
 * read (file_hash: its report's source.file_hash), then smoothed, scaled,
 * its max-mip pyramid and the ray set of the command's slices, power and
 * basis (bb_command_set_basis's when set), built by the bake's own stages
 * on threads threads (0: all cores; the same bits for any), so the
 * horizons found from them (bb_trace_horizons) are those of the bake's
 * trace. Memory: about 13 bytes per texel while building, 5.4 once
 * built, besides the height read (4). On success *pyramid and *rays receive
 * them (free with bb_pyramid_free and bb_rayset_free); the slices to trace
 * are bb_rayset_slice_count(*rays). Errors: BB_ERR_ARGUMENT (not a checked
 * bake of one file; a threads count out of range), those of the read, BB_ERR_IO
 * "PATH: the file changed while it was baked ..." when the bytes hash to
 * another file_hash, BB_ERR_MEMORY; then nothing is left allocated. */
bb_status bb_command_trace_input(const bb_command *command, int threads, uint64_t file_hash,
                                 bb_pyramid **pyramid, bb_rayset **rays, bb_error *err);

#ifdef __cplusplus
}
#endif

#endif /* BUMPBAKE_CLUSTER_H */
