#!/bin/sh
# install_test.sh - `make install` end to end, as a user of the installed library sees it:
# a DESTDIR-staged install puts the header, libhfvis.a and hfvis.pc under DESTDIR/PREFIX and the
# .pc names PREFIX with the header's version; a real install into a temporary PREFIX is found by
# pkg-config, a program written outside the tree builds with
# `cc $(pkg-config --cflags --libs hfvis)` and checks a closed-form sky-view factor; `make
# uninstall` removes the three files.
# usage: sh test/install_test.sh [BUILD [SCRATCHDIR]]   (from the repository root; the user program
# is built with $CC, default cc, and $CFLAGS: test/run.sh passes the config's, e.g. the sanitizers).
# With BUILD (e.g. build/test, as test/run.sh passes) the library already built there
# is installed; without it `make install` builds the release library first.
# Exit 0 = passed, 77 = skipped (no pkg-config), anything else = failed.
build=${1:-}
dir=${2:-${TMPDIR:-/tmp}}/install_test.$$
cc=${CC:-cc}
command -v pkg-config > /dev/null 2>&1 || { echo "skip install: pkg-config not found"; exit 77; }
[ -f hfvis.h ] && [ -f Makefile ] || { echo "install: run from the repository root"; exit 2; }
rm -rf "$dir"; mkdir -p "$dir" || exit 1
fail() { echo "FAIL install: $1"; rm -rf "$dir"; exit 1; }

# A clean make: the caller's make flags (config, -j, jobserver) do not leak into ours.
mk() { MAKEFLAGS= MFLAGS= CFLAGS= make --no-print-directory ${build:+BUILD="$build"} "$@" > "$dir/make.log" 2>&1 \
       || { cat "$dir/make.log"; fail "make $*"; }; }

version=$(awk 'NF >= 3 && $1 ~ /define$/ && $2 ~ /^HFVIS_VERSION_(MAJOR|MINOR|PATCH)$/ { v = v s $3; s = "." } END { print v }' hfvis.h)
[ -n "$version" ] || fail "no HFVIS_VERSION_MAJOR/MINOR/PATCH in hfvis.h"

# 1. DESTDIR staging: files land under DESTDIR/PREFIX, the .pc file says PREFIX.
mk install DESTDIR="$dir/stage" PREFIX=/opt/hfvis
for f in include/hfvis.h lib/libhfvis.a lib/pkgconfig/hfvis.pc; do
  [ -f "$dir/stage/opt/hfvis/$f" ] || fail "DESTDIR install did not write $f"
done
grep -qx 'prefix=/opt/hfvis' "$dir/stage/opt/hfvis/lib/pkgconfig/hfvis.pc" || fail "DESTDIR leaked into hfvis.pc"
grep -qx "Version: $version" "$dir/stage/opt/hfvis/lib/pkgconfig/hfvis.pc" || fail "hfvis.pc Version is not $version"
cmp -s hfvis.h "$dir/stage/opt/hfvis/include/hfvis.h" || fail "installed hfvis.h differs from the tree's"
mk uninstall DESTDIR="$dir/stage" PREFIX=/opt/hfvis
left=$(find "$dir/stage" -type f)
[ -z "$left" ] || fail "uninstall left $left"

# 2. A real install, used through pkg-config from outside the tree.
prefix=$dir/prefix
mk install PREFIX="$prefix"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
v=$(pkg-config --modversion hfvis) || fail "pkg-config does not find hfvis.pc"
[ "$v" = "$version" ] || fail "pkg-config --modversion says $v, hfvis.h says $version"
mkdir -p "$dir/user"
cat > "$dir/user/svf.c" << 'EOF'
/* A user program: the sky-view factor at the bottom of a pyramid pit of slope 3/4. Along the four
 * axis directions every sample of the pit wall lies on the ray z = 0.75 d, so each horizon is
 * atan(0.75), sin = 0.6, and SVF = 1 - 0.6 = 0.4 (Zaksek et al. 2011); a flat plane gives 1. */
#include <math.h>
#include <stdio.h>
#include <hfvis.h>

#define N 33              /* grid side; the pit centre is (16, 16) */
#define TOL 1e-6          /* float rounding of the horizon angle and of the SVF sum */

int main(void)
{
    static float z[N * N], svf[N * N];
    hfvis_field pit = { HFVIS_FIELD_L1_PIT, 16.0, 16.0, 0.0, 0.75, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0 };
    hfvis_field plane = { HFVIS_FIELD_PLANE, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0 };
    hfvis_grid grid;
    hfvis_status s;
    double centre, flat;

    grid.z = z; grid.width = N; grid.height = N; grid.stride = N; grid.cell_size = 1.0;
    if ((s = hfvis_field_generate(&pit, N, N, N, z)) != HFVIS_OK
        || (s = hfvis_sky_view_factor(&grid, 4, NULL, svf, N)) != HFVIS_OK) {
        printf("hfvis: %s\n", hfvis_status_string(s));
        return 1;
    }
    centre = svf[16 * N + 16];
    if ((s = hfvis_field_generate(&plane, N, N, N, z)) != HFVIS_OK
        || (s = hfvis_sky_view_factor(&grid, 4, NULL, svf, N)) != HFVIS_OK) {
        printf("hfvis: %s\n", hfvis_status_string(s));
        return 1;
    }
    flat = svf[5 * N + 7];
    printf("hfvis %d.%d.%d: pit SVF %.6f (expect 0.4), plane SVF %.6f (expect 1)\n",
           HFVIS_VERSION_MAJOR, HFVIS_VERSION_MINOR, HFVIS_VERSION_PATCH, centre, flat);
    return fabs(centre - 0.4) <= TOL && fabs(flat - 1.0) <= TOL ? 0 : 1;
}
EOF
# shellcheck disable=SC2046,SC2086 # pkg-config's output is meant to be split into words
(cd "$dir/user" && $cc -std=c99 -Wall -Wextra -Werror ${CFLAGS:-} svf.c $(pkg-config --cflags --libs hfvis) -o svf) \
  > "$dir/cc.log" 2>&1 || { cat "$dir/cc.log"; fail "the user program does not build against the installed library"; }
"$dir/user/svf" || fail "the user program's check failed"
mk uninstall PREFIX="$prefix"
[ ! -e "$prefix/include/hfvis.h" ] && [ ! -e "$prefix/lib/libhfvis.a" ] && [ ! -e "$prefix/lib/pkgconfig/hfvis.pc" ] \
  || fail "uninstall left files in $prefix"
rm -rf "$dir"
echo "ok   install (DESTDIR staging, pkg-config $version, user program, uninstall)"
