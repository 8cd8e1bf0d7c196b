/* file_names.h: the one way the library splits a path into its last
 * component and that component's extension. Python's os.path has the
 * same rule: a dot that begins the name (".png", ".hidden") starts no
 * extension. */
#ifndef BB_CORE_FILE_NAMES_H
#define BB_CORE_FILE_NAMES_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The last component of path (after its last '/'). */
const char *bb__file_name(const char *path);

/* The directory part of path ("." when none, "/" for a file at the
 * root) into dir (capacity cap). */
void bb__directory_part(const char *path, char *dir, size_t cap);

/* The dot that starts the extension of path's last component, or NULL
 * when it has none. */
const char *bb__file_extension(const char *path);

/* 1 when path's extension is ext (without its dot), whatever the case. */
int bb__path_has_extension(const char *path, const char *ext);

#ifdef __cplusplus
}
#endif

#endif
