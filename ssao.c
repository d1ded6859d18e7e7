/* ssao.c - screen space. Part of hfvis (see hfvis.h).
 *
 * Contents (built by the screen-space and Laine-Karras issues)
 *   1. Camera, depth linearisation, view-space reconstruction
 *   2. The line lattice in screen space (P3)
 *   3. P3 line-sweep AO; HBAO; the screen-space ray-traced reference
 *   4. P4 far-field AO and the mipmap baseline
 *   5. Laine-Karras bitmask ray-cast AO
 * This file holds no code yet; it compiles to an empty object so that vendoring the four files
 * works from the first release. */
#include "hfvis.h"
typedef int hfvis__ssao_empty_translation_unit; /* ISO C forbids an empty translation unit */
