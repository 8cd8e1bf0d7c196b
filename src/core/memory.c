/* memory.c: how much this process may still allocate (the machine's
 * MemAvailable, its cgroups' limits, RLIMIT_AS), so that a bake too large
 * for the machine or container is refused with the figures before
 * anything is allocated, never ended by the kernel's out-of-memory killer. */
#include "core/internal.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

/* ROOT + path into out ("" root: the system's own files). */
static int under(const char *root, const char *path, char *out, size_t cap) {
  return snprintf(out, cap, "%s%s", root, path) < (int)cap ? 0 : -1;
}

/* MemAvailable of ROOT/proc/meminfo in bytes (the kernel's estimate of
 * what can be allocated without swapping, page cache included); 0 when
 * unknown. */
static uint64_t mem_available(const char *root) {
  char path[PATH_MAX];
  FILE *f = under(root, "/proc/meminfo", path, sizeof path) == 0 ? fopen(path, "r") : NULL;
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

/* ---------------------------------------------------------------- cgroups */

/* A container's memory limit is its cgroup's, which neither MemAvailable
 * (the whole machine's) nor RLIMIT_AS shows: a bake over it is killed by
 * the kernel with no message. Every cgroup from the process's own up to
 * its hierarchy's root may set one (v2: memory.max; v1, with the memory
 * controller: memory.limit_in_bytes); the room under each is its limit
 * less what the group uses, its page cache (active_file and
 * inactive_file: file pages the kernel reclaims before it kills anything)
 * not counted, as MemAvailable counts the machine's. cgroup v1 names the
 * same counts with a total_ prefix for the group and its children, as
 * memory.usage_in_bytes counts them; its unprefixed ones are the group's
 * own pages alone. */

/* The number at the start of DIR/NAME; 0 when it reads, -1 when missing
 * or "max" (no limit) or not a number. */
static int read_number(const char *dir, const char *name, uint64_t *value) {
  char path[PATH_MAX];
  if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path)
    return -1;
  FILE *f = fopen(path, "r");
  if (!f)
    return -1;
  unsigned long long v = 0;
  const int ok = fscanf(f, "%llu", &v) == 1;
  fclose(f);
  *value = v;
  return ok ? 0 : -1;
}

/* The value of KEY in DIR/memory.stat ("KEY N" lines); 0 when absent. */
static uint64_t stat_value(const char *dir, const char *key) {
  char path[PATH_MAX], line[256], name[128];
  unsigned long long v;
  uint64_t found = 0;
  if (snprintf(path, sizeof path, "%s/memory.stat", dir) >= (int)sizeof path)
    return 0;
  FILE *f = fopen(path, "r");
  if (!f)
    return 0;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, "%127s %llu", name, &v) == 2 && strcmp(name, key) == 0) {
      found = v;
      break;
    }
  fclose(f);
  return found;
}

/* The room under one cgroup directory's limit, or UINT64_MAX when it sets
 * none. */
static uint64_t group_room(const char *dir, int v2) {
  uint64_t limit, usage = 0;
  if (read_number(dir, v2 ? "memory.max" : "memory.limit_in_bytes", &limit) != 0)
    return UINT64_MAX;
  (void)read_number(dir, v2 ? "memory.current" : "memory.usage_in_bytes", &usage);
  uint64_t cache =
      v2 ? 0
         : stat_value(dir, "total_active_file") + stat_value(dir, "total_inactive_file");
  if (!cache)
    cache = stat_value(dir, "active_file") + stat_value(dir, "inactive_file");
  const uint64_t used = usage > cache ? usage - cache : 0;
  return limit > used ? limit - used : 0;
}

/* Undoes mountinfo's octal escapes ("\040" a space) in place. */
static void unescape(char *s) {
  char *out = s;
  for (; *s; s++, out++) {
    if (s[0] == '\\' && s[1] >= '0' && s[1] <= '3' && s[2] >= '0' && s[2] <= '7' &&
        s[3] >= '0' && s[3] <= '7') {
      *out = (char)((s[1] - '0') * 64 + (s[2] - '0') * 8 + (s[3] - '0'));
      s += 3;
    } else {
      *out = *s;
    }
  }
  *out = '\0';
}

/* 1 when the comma-separated list holds word. */
static int has_word(const char *list, const char *word) {
  const size_t n = strlen(word);
  for (const char *p = list; p && *p;) {
    if (strncmp(p, word, n) == 0 && (p[n] == ',' || p[n] == '\0'))
      return 1;
    p = strchr(p, ',');
    p = p ? p + 1 : NULL;
  }
  return 0;
}

/* The process's path in a hierarchy, from ROOT/proc/self/cgroup: v2's
 * "0::PATH" line, or the v1 line whose controllers include memory. */
static int own_group(const char *root, int v2, char *out, size_t cap) {
  char path[PATH_MAX], line[PATH_MAX + 256];
  FILE *f = under(root, "/proc/self/cgroup", path, sizeof path) == 0 ? fopen(path, "r") : NULL;
  if (!f)
    return -1;
  int found = -1;
  while (found != 0 && fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = '\0';
    char *controllers = strchr(line, ':');
    char *group = controllers ? strchr(controllers + 1, ':') : NULL;
    if (!group)
      continue;
    *group++ = '\0';
    *controllers++ = '\0';
    const int match = v2 ? strcmp(line, "0") == 0 && *controllers == '\0'
                         : has_word(controllers, "memory");
    if (match && snprintf(out, cap, "%s", group) < (int)cap)
      found = 0;
  }
  fclose(f);
  return found;
}

/* The smallest room under the limits of the process's cgroups, from
 * every cgroup mount in ROOT/proc/self/mountinfo that holds memory
 * limits (cgroup2; cgroup v1 with the memory controller), each group from
 * the process's own up to the mount's top; UINT64_MAX when none sets one.
 * *file: which file set the smallest. */
static uint64_t cgroup_room(const char *root, const char **file) {
  char path[PATH_MAX], line[3 * PATH_MAX];
  FILE *f = under(root, "/proc/self/mountinfo", path, sizeof path) == 0 ? fopen(path, "r") : NULL;
  uint64_t best = UINT64_MAX;
  if (!f)
    return best;
  while (fgets(line, sizeof line, f)) {
    /* ID PARENT MAJ:MIN ROOT MOUNTPOINT OPTIONS [OPTIONAL...] - TYPE SOURCE SUPER */
    char *fields[6] = {0}, *save = NULL;
    line[strcspn(line, "\n")] = '\0';
    char *dash = strstr(line, " - ");
    if (!dash)
      continue;
    *dash = '\0';
    char *fstype = strtok_r(dash + 3, " ", &save), *source = strtok_r(NULL, " ", &save);
    char *super = strtok_r(NULL, " ", &save);
    (void)source;
    save = NULL;
    int n = 0;
    for (char *t = strtok_r(line, " ", &save); t && n < 6; t = strtok_r(NULL, " ", &save))
      fields[n++] = t;
    if (n < 5 || !fstype)
      continue;
    const int v2 = strcmp(fstype, "cgroup2") == 0;
    if (!v2 && !(strcmp(fstype, "cgroup") == 0 && super && has_word(super, "memory")))
      continue;
    char group[PATH_MAX], mount_root[PATH_MAX], dir[3 * PATH_MAX];
    if (own_group(root, v2, group, sizeof group) != 0)
      continue;
    snprintf(mount_root, sizeof mount_root, "%s", fields[3]);
    unescape(mount_root);
    unescape(fields[4]);
    /* The group's path below the mount's root ("/" mounts the whole tree). */
    size_t r = strcmp(mount_root, "/") == 0 ? 0 : strlen(mount_root);
    if (strncmp(group, mount_root, r) != 0 || (group[r] != '/' && group[r] != '\0'))
      continue;
    const int top = snprintf(dir, sizeof dir, "%s%s", root, fields[4]);
    if (top < 0 || snprintf(dir + top, sizeof dir - (size_t)top, "%s", group + r) >=
                       (int)(sizeof dir - (size_t)top))
      continue;
    /* This group, then each parent up to the mount point. */
    for (size_t len = strlen(dir); len >= (size_t)top; ) {
      dir[len] = '\0';
      const uint64_t room = group_room(dir, v2);
      if (room < best) {
        best = room;
        *file = v2 ? "cgroup memory.max" : "cgroup memory.limit_in_bytes";
      }
      char *slash = strrchr(dir, '/');
      if (!slash || (size_t)(slash - dir) < (size_t)top)
        break;
      len = (size_t)(slash - dir);
    }
  }
  fclose(f);
  return best;
}

bb_status bb__memory_available_at(const char *root, uint64_t *bytes, const char **source,
                                  bb_error *err) {
  if (!bytes)
    return bb__fail(err, BB_ERR_ARGUMENT, "memory: bytes is NULL");
  const char *from = "MemAvailable";
  uint64_t room = mem_available(root);
  if (!room) { /* no /proc: free pages, which leaves out the page cache */
    const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) {
      room = (uint64_t)pages * (uint64_t)page;
      from = "sysconf free pages";
    }
  }
  const char *group_file = NULL;
  const uint64_t group = cgroup_room(root, &group_file);
  if (group_file && (!room || group < room)) {
    room = group;
    from = group_file;
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
  if (!room && strcmp(from, "MemAvailable") == 0)
    return bb__fail(err, BB_ERR_IO, "memory: cannot tell what is available (no "
                                    "/proc/meminfo, no free page count)");
  *bytes = room;
  if (source)
    *source = from;
  return BB_OK;
}

bb_status bb__memory_available(uint64_t *bytes, const char **source, bb_error *err) {
  return bb__memory_available_at("", bytes, source, err);
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
  if (bb__memory_available(&room, &source, NULL) != BB_OK)
    return BB_OK; /* nothing to judge by: the allocations themselves will say */
  if (need <= (double)room)
    return BB_OK;
  char a[32], b[32];
  size_text(need, a, sizeof a);
  size_text((double)room, b, sizeof b);
  return bb__fail(err, BB_ERR_MEMORY, "%s needs about %s of memory; %s is available (%s)",
                  what, a, b, source);
}

int bb__memory_note(double need, const char *what, char *out, size_t cap) {
  if (cap)
    out[0] = '\0';
  if (need <= (double)BB_MAX_READ_BYTES || !cap)
    return 0;
  char a[32], b[32] = "";
  size_text(need, a, sizeof a);
  uint64_t room = 0;
  if (bb__memory_available(&room, NULL, NULL) == BB_OK)
    size_text((double)room, b, sizeof b);
  snprintf(out, cap, "%s takes about %s of memory%s%s%s", what, a, b[0] ? " (" : "", b,
           b[0] ? " is available)" : "");
  return 1;
}
