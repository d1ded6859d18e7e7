#!/bin/sh
# tiles.sh - the tile list of a tiled hfvis run (docs/tiles.md): one "X0,Y0,W,H" per line, the
# tiles covering RASTER exactly (row by row, the last column and row narrower), each small enough
# that its grid (the tile plus a halo on every side) fits the memory budget of one task.
#
# usage: sh examples/tiles.sh [-b BYTES_PER_CELL] [-c CELL] RASTER R BUDGET
#   RASTER  any raster hfvis reads (its width, height and cell come from 'hfvis info RASTER')
#   R       the search radius, --max-distance R, in the raster's units (metres when projected)
#   BUDGET  memory of one task, bytes with an optional K, M, G or T (powers of 1024), as --max-memory
#   -b B    bytes per grid cell that hfvis estimates for the command (default 84: skyview, sky,
#           shadow, light, hillshade, openness; visibility and indirect 100; horizon 152 + 4 K;
#           README, "Tiles": the figure --max-memory is checked against)
#   -c CELL the cell size when RASTER has no georeference (PFM, PGM), as --cell
# The halo is ceil(R / cell) + 5 cells (hfvis_tile_halo in lattice mode; --exact needs 3 fewer); a tile of S x S cells loads at
# most (S + 2 halo)^2 cells, so S = floor(sqrt(BUDGET / B)) - 2 halo.
# HFVIS names the hfvis program (default: hfvis on the PATH).
# Example: sh examples/tiles.sh dtm.tif 1000 4G > tiles.txt
hfvis=${HFVIS:-hfvis}
bpc=84
cell=
while [ $# -gt 0 ]; do
  case $1 in
    -b) bpc=$2; shift 2 ;;
    -c) cell=$2; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "tiles.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
if [ $# -ne 3 ]; then echo "usage: sh examples/tiles.sh [-b BYTES_PER_CELL] [-c CELL] RASTER R BUDGET" >&2; exit 2; fi
info=$("$hfvis" info "$1") || exit 1
printf '%s\n' "$info" | awk -v R="$2" -v budget="$3" -v bpc="$bpc" -v cellflag="$cell" '
  $1 == "width" { W = $2 } $1 == "height" { H = $2 } $1 == "cell" { cell = $2 }
  END {
    if (cellflag != "") cell = cellflag
    if (cell == "none" || cell == "" || cell + 0 <= 0) { print "tiles.sh: the raster has no cell size: give -c CELL" > "/dev/stderr"; exit 2 }
    if (R !~ /^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$/ || R + 0 <= 0) { print "tiles.sh: R must be a distance > 0, got " R > "/dev/stderr"; exit 2 }
    if (bpc !~ /^[0-9]+$/ || bpc + 0 < 1) { print "tiles.sh: -b must be a whole number of bytes >= 1" > "/dev/stderr"; exit 2 }
    b = budget; m = 1; u = toupper(substr(b, length(b), 1))
    if (u == "K") m = 1024; else if (u == "M") m = 1024 ^ 2; else if (u == "G") m = 1024 ^ 3; else if (u == "T") m = 1024 ^ 4
    if (m > 1) b = substr(b, 1, length(b) - 1)
    if (b !~ /^[0-9]*\.?[0-9]+$/) { print "tiles.sh: BUDGET must be bytes with an optional K, M, G or T, got " budget > "/dev/stderr"; exit 2 }
    bytes = b * m
    q = R / cell; halo = int(q); if (halo < q) halo++; halo += 5        # ceil(R / cell) + 5, hfvis_tile_halo (lattice)
    g = int(sqrt(bytes / bpc)); while ((g + 1) * (g + 1) * bpc <= bytes) g++; while (g > 0 && g * g * bpc > bytes) g--
    S = g - 2 * halo
    if (S < 1) { printf "tiles.sh: %s bytes hold a grid of %d x %d cells, not even one cell with its halo of %d on each side: raise the budget\n", budget, g, g, halo > "/dev/stderr"; exit 1 }
    for (y = 0; y < H; y += S) for (x = 0; x < W; x += S)
      printf "%d,%d,%d,%d\n", x, y, (x + S <= W ? S : W - x), (y + S <= H ? S : H - y)
  }'
