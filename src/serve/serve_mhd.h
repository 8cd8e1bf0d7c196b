/* serve_mhd.h: libmicrohttpd, loaded when `bumpbake serve` starts
 * (serve_mhd.c) instead of linked into the program.
 *
 * Why: linked, it, GnuTLS and the eight libraries GnuTLS needs (10 in all)
 * joined every bumpbake process's global scope, which each of the ~168,000
 * symbol lookups made when the OpenImageIO module is loaded walks first:
 * 60 M instructions of a bake's start-up (docs/performance.md, 2026-12-08).
 * Only serve needs it.
 *
 * serve_http.c includes this (it includes <microhttpd.h>): each call it
 * makes is then a call through serve_mhd, filled by serve_mhd_load. */
#ifndef BB_SERVE_MHD_H
#define BB_SERVE_MHD_H

#include <microhttpd.h>
#include <stddef.h>

/* Every libmicrohttpd function serve calls. */
#define SERVE_MHD_CALLS(X)                                                                    \
  X(MHD_add_response_header)                                                                  \
  X(MHD_create_response_from_buffer)                                                          \
  X(MHD_create_response_from_callback)                                                        \
  X(MHD_destroy_response)                                                                     \
  X(MHD_get_connection_info)                                                                  \
  X(MHD_get_connection_values_n)                                                              \
  X(MHD_get_daemon_info)                                                                      \
  X(MHD_lookup_connection_value)                                                              \
  X(MHD_queue_response)                                                                       \
  X(MHD_resume_connection)                                                                    \
  X(MHD_start_daemon)                                                                         \
  X(MHD_stop_daemon)                                                                          \
  X(MHD_suspend_connection)

#define SERVE_MHD_MEMBER(name) __typeof__(name) *name;
typedef struct serve_mhd_calls {
  SERVE_MHD_CALLS(SERVE_MHD_MEMBER)
} serve_mhd_calls;
#undef SERVE_MHD_MEMBER

extern serve_mhd_calls serve_mhd;

/* Loads libmicrohttpd (its soname, BB_MHD_SONAME, from the system's library
 * folders, once): 1, or 0 and why in why (cap bytes), one line. */
int serve_mhd_load(char *why, size_t cap);

#ifndef SERVE_MHD_LOADER
#define MHD_add_response_header (serve_mhd.MHD_add_response_header)
#define MHD_create_response_from_buffer (serve_mhd.MHD_create_response_from_buffer)
#define MHD_create_response_from_callback (serve_mhd.MHD_create_response_from_callback)
#define MHD_destroy_response (serve_mhd.MHD_destroy_response)
#define MHD_get_connection_info (serve_mhd.MHD_get_connection_info)
#define MHD_get_connection_values_n (serve_mhd.MHD_get_connection_values_n)
#define MHD_get_daemon_info (serve_mhd.MHD_get_daemon_info)
#define MHD_lookup_connection_value (serve_mhd.MHD_lookup_connection_value)
#define MHD_queue_response (serve_mhd.MHD_queue_response)
#define MHD_resume_connection (serve_mhd.MHD_resume_connection)
#define MHD_start_daemon (serve_mhd.MHD_start_daemon)
#define MHD_stop_daemon (serve_mhd.MHD_stop_daemon)
#define MHD_suspend_connection (serve_mhd.MHD_suspend_connection)
#endif

#endif /* BB_SERVE_MHD_H */
