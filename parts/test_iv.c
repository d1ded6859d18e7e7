#include "hfvis.h"
#include "test.h"
int main(void){ printf("%g\n", hfvis_iv_bias_half_diagonal(NULL)); return 0; }
