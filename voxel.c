/* voxel.c - meshes and volumes. Part of hfvis (see hfvis.h).
 *
 * Contents (built by the meshes/voxelization and visibility-field issues)
 *   1. Mesh type and OBJ codec
 *   2. BVH and ray casting; reference rasterizer
 *   3. Surface, conservative and solid voxelization; the Volume Buffer
 *   4. Incremental voxelization
 *   5. 4D visibility fields
 *   6. Volume VPL indirect light
 * This file holds no code yet; it compiles to an empty object so that vendoring the four files
 * works from the first release. */
#include "hfvis.h"
typedef int hfvis__voxel_empty_translation_unit; /* ISO C forbids an empty translation unit */
