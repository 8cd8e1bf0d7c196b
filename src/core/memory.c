/* memory.c: how much this process may still allocate, so that a bake too
 * large for the machine is refused with the figures before anything is
 * allocated, never ended by the kernel's out-of-memory killer. */
#include "core/internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

/* MemAvailable of /proc/meminfo in bytes (the kernel's estimate of what can
 * be allocated without swapping, page cache included); 0 when unknown. */
static uint64_t mem_available(void) {
  FILE *f = fopen("/proc/meminfo", "r");
  if (!f)
    return 0;
  char line[256];
  unsigned long long kib = 0;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, "MemAvailable: %llu kB", &kib) == 1)
      break;
  fclose(f);
  return (uint64_t)kib * 1024u;
}

/* Bytes of address space this process maps now (/proc/self/statm). */
static uint64_t address_space_used(void) {
  FILE *f = fopen("/proc/self/statm", "r");
  unsigned long long pages = 0;
  if (f) {
    if (fscanf(f, "%llu", &pages) != 1)
      pages = 0;
    fclose(f);
  }
  const long page = sysconf(_SC_PAGESIZE);
  return (uint64_t)pages * (uint64_t)(page > 0 ? page : 4096);
}

bb_status bb_memory_available(uint64_t *bytes, const char **source, bb_error *err) {
  if (!bytes)
    return bb__fail(err, BB_ERR_ARGUMENT, "memory: bytes is NULL");
  const char *from = "MemAvailable";
  uint64_t room = mem_available();
  if (!room) { /* no /proc: free pages, which leaves out the page cache */
    const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) {
      room = (uint64_t)pages * (uint64_t)page;
      from = "sysconf free pages";
    }
  }
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    const uint64_t used = address_space_used(), limit = (uint64_t)rl.rlim_cur;
    const uint64_t left = limit > used ? limit - used : 0;
    if (!room || left < room) {
      room = left;
      from = "RLIMIT_AS";
    }
  }
  if (!room && strcmp(from, "RLIMIT_AS") != 0)
    return bb__fail(err, BB_ERR_IO, "memory: cannot tell what is available (no "
                                    "/proc/meminfo, no free page count)");
  *bytes = room;
  if (source)
    *source = from;
  return BB_OK;
}

/* "12.3 GiB" or "640 MiB". */
static void size_text(double bytes, char *out, size_t cap) {
  const double gib = bytes / (1024.0 * 1024.0 * 1024.0);
  if (gib >= 1.0)
    snprintf(out, cap, "%.1f GiB", gib);
  else
    snprintf(out, cap, "%.0f MiB", bytes / (1024.0 * 1024.0));
}

bb_status bb__memory_check(double need, const char *what, bb_error *err) {
  uint64_t room = 0;
  const char *source = NULL;
  if (bb_memory_available(&room, &source, NULL) != BB_OK)
    return BB_OK; /* nothing to judge by: the allocations themselves will say */
  if (need <= (double)room)
    return BB_OK;
  char a[32], b[32];
  size_text(need, a, sizeof a);
  size_text((double)room, b, sizeof b);
  return bb__fail(err, BB_ERR_MEMORY, "%s needs about %s of memory; %s is available (%s)",
                  what, a, b, source);
}
