/* test_dir.h - the directory helper of the file tests (POSIX dirent), kept out of test.h so the
 * harness itself needs no POSIX header. */
#ifndef HFVIS_TEST_DIR_H
#define HFVIS_TEST_DIR_H
#include <dirent.h>
#include <stdio.h>
#include <string.h>

/* Entries of a directory except . and .. (-1 if it cannot be opened). */
static int test_dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    if (!d) return -1;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) n++;
    closedir(d);
    return n;
}

/* "dir/name" in one of 8 rotating buffers (a call's result stays valid for 7 more calls). */
static inline char *test_dir_path(const char *dir, const char *name)
{
    static char p[8][512];
    static int k;
    k = (k + 1) & 7;
    snprintf(p[k], sizeof p[k], "%s/%s", dir, name);
    return p[k];
}

#endif
