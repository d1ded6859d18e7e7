#!/bin/sh
# gallery.sh BUILD DEST - `make gallery`: runs the examples in BUILD/examples into out/gallery and
# copies one PNG per capability into DEST (docs/gallery) under the names README's Gallery shows,
# then validates them with test/png_check.sh. Every image is deterministic: rerunning it on the
# same build rewrites the same bytes.
set -e
build=${1:-build}; dest=${2:-docs/gallery}
work=out/gallery
rm -rf "$work"
mkdir -p "$work" "$dest"
for e in "$build"/examples/[0-9][0-9]_*; do
  echo "gallery: $e $work"
  "$e" "$work" > "$work/$(basename "$e").log" || { cat "$work/$(basename "$e").log"; exit 1; }
done
rm -f "$dest"/*.png
# gallery name            example output
while read -r name from; do
  cp "$work/$from" "$dest/$name"
done <<'LIST'
horizon.png               01_horizon_sheet.png
sky_view.png              02_sky_sheet.png
environment_light.png     03_environment_light_rgb.png
sun_shadows.png           04_sun_sheet.png
terrain_bounces.png       05_sheet.png
lava.png                  06_lava_scene_rgb.png
visibility_index.png      07_visibility_index.png
voxels.png                08_teapot_conservative.png
voxels_solid.png          08_torus_solid.png
ns_gi.png                 gi_side_by_side.png
ssao.png                  ssao_sheet.png
volume_gi.png             volgi_sheet.png
visibility_field.png      12_visibility_field_sheet.png
mesh_ao.png               lk_sheet.png
exact_rays.png            14_exact_sheet.png
LIST
rc=0; sh test/png_check.sh "$dest" || rc=$?
if [ "$rc" -ne 0 ] && [ "$rc" -ne 77 ]; then exit 1; fi
ls -l "$dest"/*.png | awk '{ total += $5; printf "gallery: %8d bytes  %s\n", $5, $NF } END { printf "gallery: %8d bytes in all\n", total }'
