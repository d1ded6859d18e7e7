/* test_dir.h - the directory helper of the file tests (POSIX dirent), kept out of test.h so the
 * harness itself needs no POSIX header. */
#ifndef HFVIS_TEST_DIR_H
#define HFVIS_TEST_DIR_H
#include <dirent.h>
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

#endif
