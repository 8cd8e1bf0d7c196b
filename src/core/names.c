/* names.c: the one way the library parses a name into an enum value, so
 * every parser refuses the same way, with the names it accepts. */
#include "core/internal.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

bb_status bb__parse_name(const char *what, const char *name, const char *const *names,
                         int count, int ignore_case, int *index, bb_error *err) {
  for (int i = 0; name && i < count; i++)
    if (names[i] && (ignore_case ? strcasecmp(name, names[i]) : strcmp(name, names[i])) == 0) {
      *index = i;
      return BB_OK;
    }
  char list[256] = "";
  size_t used = 0;
  for (int i = 0; i < count && used < sizeof list; i++)
    if (names[i])
      used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", used ? ", " : "",
                               names[i]);
  if (!name)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: no name given (one of %s)", what, list);
  return bb__fail(err, BB_ERR_ARGUMENT, "%s must be one of %s (got '%.64s')", what, list, name);
}
