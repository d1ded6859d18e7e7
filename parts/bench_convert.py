#!/usr/bin/env python3
"""parts/bench_NAME.c -> examples/bench_NAME.c: drop its main, export bench_NAME(int quick)
(declared in examples/bench.h)."""
import sys, re, os
os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
for name in sys.argv[1:]:
    s = open('parts/bench_%s.c' % name).read()
    i = s.rfind('\nint main(')
    if i >= 0: s = s[:i + 1].rstrip() + '\n'
    s = s.replace('static void bench_%s(int quick)' % name, 'void bench_%s(int quick)' % name)
    s = s.replace('#include "hfvis.h"\n', '#include "bench.h"\n#include "hfvis.h"\n', 1)
    open('examples/bench_%s.c' % name, 'w').write(s)
    h = open('examples/bench.h').read()
    decl = 'void bench_%s(int quick);\n' % name
    if decl not in h:
        h = h.replace('#endif', decl + '#endif')
        open('examples/bench.h', 'w').write(h)
    print('bench:', name)
