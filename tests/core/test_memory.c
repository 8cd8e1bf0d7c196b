/* test_memory.c: what bb__memory_available finds under a container's memory
 * limit. In a 450 MB memory cgroup a 4096 x 4096 bake was killed by the
 * kernel with no message: only MemAvailable and RLIMIT_AS were read. The
 * reader takes a scratch_dir directory, so each case is a made-up /proc and
 * /sys/fs/cgroup tree (cgroup v2 and v1, limits set above the process's own
 * group, a container's mount of its own subtree); `make hostile` runs a bake
 * in a real one. */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include <criterion/criterion.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/internal.h"
#include "scratch_dir.h"

#define MIB (1024.0 * 1024.0)

static void make_scratch_dir(void) { scratch_dir_make("bb_memory"); }

TestSuite(memory, .init = make_scratch_dir, .fini = scratch_dir_remove);

/* Writes text to ROOT/path, making its directories. */
static void put(const char *path, const char *text) {
  char full[512];
  snprintf(full, sizeof full, "%s/%s", scratch_dir, path);
  for (char *s = full + strlen(scratch_dir) + 1; (s = strchr(s, '/')) != NULL; s++) {
    *s = '\0';
    mkdir(full, 0755);
    *s = '/';
  }
  FILE *f = fopen(full, "w");
  cr_assert_not_null(f, "%s", full);
  fputs(text, f);
  cr_assert_eq(fclose(f), 0);
}

/* What the reader says under ROOT, in MiB, and from where. */
static double available(const char **source) {
  uint64_t bytes = 0;
  bb_error err = {{0}};
  cr_assert_eq(bb__memory_available_at(scratch_dir, &bytes, source, &err), BB_OK, "%s", err.message);
  return (double)bytes / MIB;
}

static void machine(void) {
  put("proc/meminfo", "MemTotal:       25165824 kB\nMemAvailable:    8388608 kB\n");
}

Test(memory, a_cgroup_v2_limit_above_the_process_group_counts) {
  machine();
  put("proc/self/cgroup", "0::/batch/job7\n");
  put("proc/self/mountinfo",
      "22 1 0:20 / / rw - ext4 /dev/scratch_dir rw\n"
      "30 22 0:26 / /sys/fs/cgroup rw,nosuid - cgroup2 cgroup2 rw,nsdelegate\n");
  put("sys/fs/cgroup/batch/job7/memory.max", "max\n");
  put("sys/fs/cgroup/batch/job7/memory.current", "104857600\n");
  /* the limit is the parent's: 450 MiB, 100 MiB used of which 20 MiB is
   * page cache the kernel can drop */
  put("sys/fs/cgroup/batch/memory.max", "471859200\n");
  put("sys/fs/cgroup/batch/memory.current", "104857600\n");
  put("sys/fs/cgroup/batch/memory.stat", "anon 83886080\nfile 20971520\ninactive_file 20971520\n");
  const char *source = NULL;
  cr_expect_float_eq(available(&source), 450.0 - 80.0, 1e-9);
  cr_expect_str_eq(source, "cgroup memory.max");
}

Test(memory, a_cgroup_v1_limit_less_its_usage) {
  machine();
  put("proc/self/cgroup", "5:devices:/docker/c1\n4:cpu,memory:/docker/c1\n0::/\n");
  put("proc/self/mountinfo",
      "31 23 0:28 / /sys/fs/cgroup rw - tmpfs tmpfs rw,mode=755\n"
      "32 31 0:29 / /sys/fs/cgroup/cpu,memory rw,relatime shared:9 - cgroup cgroup rw,cpu,memory\n"
      "41 31 0:38 / /sys/fs/cgroup/unified rw,relatime - cgroup2 cgroup2 rw\n");
  put("sys/fs/cgroup/cpu,memory/memory.limit_in_bytes", "9223372036854771712\n");
  put("sys/fs/cgroup/cpu,memory/docker/c1/memory.limit_in_bytes", "1073741824\n");
  put("sys/fs/cgroup/cpu,memory/docker/c1/memory.usage_in_bytes", "314572800\n");
  put("sys/fs/cgroup/cpu,memory/docker/c1/memory.stat",
      "cache 0\ninactive_file 5\ntotal_inactive_file 104857600\n");
  /* cgroup v2 holds no limit here (no memory.max at its scratch_dir) */
  const char *source = NULL;
  cr_expect_float_eq(available(&source), 1024.0 - 200.0, 1e-9);
  cr_expect_str_eq(source, "cgroup memory.limit_in_bytes");
}

/* The kernel reclaims a group's page cache, active or not, before it
 * kills anything: a 3.0 GB cgroup v1 limit with 2.74 GB used, 2.17 GB of
 * it active_file, has 2.5 GB of room, not the 0.26 GB that refused a
 * 4096 x 4096 bake ("needs about 637 MiB; 369 MiB is available"). cgroup
 * v2 counts both the same way. */
Test(memory, page_cache_active_or_not_counts_as_room) {
  machine();
  put("proc/self/cgroup", "4:memory:/docker/c1\n");
  put("proc/self/mountinfo",
      "32 31 0:29 / /sys/fs/cgroup/memory rw - cgroup cgroup rw,memory\n");
  put("sys/fs/cgroup/memory/docker/c1/memory.limit_in_bytes",
      "3221225472\n"); /* 3072 MiB */
  put("sys/fs/cgroup/memory/docker/c1/memory.usage_in_bytes",
      "2942304256\n"); /* 2806 MiB */
  put("sys/fs/cgroup/memory/docker/c1/memory.stat",
      "cache 2600000000\nactive_file 1\ninactive_file 1\n"
      "total_active_file 2275409920\ntotal_inactive_file 104857600\n"); /* 2170 + 100 MiB
                                                                         */
  const char *source = NULL;
  cr_expect_float_eq(available(&source), 3072.0 - (2806.0 - 2270.0), 1e-9);
  cr_expect_str_eq(source, "cgroup memory.limit_in_bytes");
  /* Without the total_ counts (no children to sum), the group's own. */
  put("sys/fs/cgroup/memory/docker/c1/memory.stat",
      "active_file 2275409920\ninactive_file 104857600\n");
  cr_expect_float_eq(available(&source), 3072.0 - (2806.0 - 2270.0), 1e-9);
  /* cgroup v2: memory.stat's active_file and inactive_file. */
  put("proc/self/cgroup", "0::/job\n");
  put("proc/self/mountinfo", "30 22 0:26 / /sys/fs/cgroup rw - cgroup2 cgroup2 rw\n");
  put("sys/fs/cgroup/job/memory.max", "3221225472\n");
  put("sys/fs/cgroup/job/memory.current", "2942304256\n");
  put("sys/fs/cgroup/job/memory.stat", "anon 500000000\nfile 2380267520\nactive_file "
                                       "2275409920\ninactive_file 104857600\n");
  cr_expect_float_eq(available(&source), 3072.0 - (2806.0 - 2270.0), 1e-9);
  cr_expect_str_eq(source, "cgroup memory.max");
}

/* Inside a container the cgroup file system is often its own subtree,
 * mounted at /sys/fs/cgroup/memory with mountinfo's scratch_dir naming it. */
Test(memory, a_container_mounting_its_own_subtree) {
  machine();
  put("proc/self/cgroup", "9:memory:/kubepods/pod1/c2\n");
  put("proc/self/mountinfo",
      "35 31 0:32 /kubepods/pod1/c2 /sys/fs/cgroup/my\\040memory ro - cgroup cgroup rw,memory\n");
  put("sys/fs/cgroup/my memory/memory.limit_in_bytes", "471859200\n");
  put("sys/fs/cgroup/my memory/memory.usage_in_bytes", "0\n");
  const char *source = NULL;
  cr_expect_float_eq(available(&source), 450.0, 1e-9);
  cr_expect_str_eq(source, "cgroup memory.limit_in_bytes");
}

Test(memory, no_limit_leaves_memavailable_and_a_full_group_leaves_nothing) {
  machine();
  put("proc/self/cgroup", "0::/user.slice\n");
  put("proc/self/mountinfo", "30 22 0:26 / /sys/fs/cgroup rw - cgroup2 cgroup2 rw\n");
  put("sys/fs/cgroup/user.slice/memory.max", "max\n");
  const char *source = NULL;
  cr_expect_float_eq(available(&source), 8192.0, 1e-9);
  cr_expect_str_eq(source, "MemAvailable");
  /* A limit above the machine's room: the machine's room. */
  put("sys/fs/cgroup/user.slice/memory.max", "17179869184\n");
  cr_expect_float_eq(available(&source), 8192.0, 1e-9);
  cr_expect_str_eq(source, "MemAvailable");
  /* Using more than the limit (it was lowered): nothing left, said so. */
  put("sys/fs/cgroup/user.slice/memory.max", "104857600\n");
  put("sys/fs/cgroup/user.slice/memory.current", "209715200\n");
  cr_expect_float_eq(available(&source), 0.0, 1e-9);
  cr_expect_str_eq(source, "cgroup memory.max");
  /* A group elsewhere in the hierarchy (another process's) is not ours. */
  put("proc/self/cgroup", "0::/other.slice\n");
  cr_expect_float_eq(available(&source), 8192.0, 1e-9);
}

/* What the bake's refusal then says: the figures and the cgroup. */
Test(memory, the_refusal_names_the_cgroup) {
  machine();
  put("proc/self/cgroup", "0::/\n");
  put("proc/self/mountinfo", "30 22 0:26 / /sys/fs/cgroup rw - cgroup2 cgroup2 rw\n");
  put("sys/fs/cgroup/memory.max", "471859200\n");
  const char *source = NULL;
  cr_expect_float_eq(available(&source), 450.0, 1e-9);
  cr_expect_str_eq(source, "cgroup memory.max");
}
