// Compile-only check: hfvis.h must be valid C++ (STYLE.md, compile-only tests).
#include "hfvis.h"
int main() { hfvis_sweep_options o = hfvis_sweep_options_default(); return (int)o.border + (int)hfvis_status_string(HFVIS_OK)[0] * 0; }
