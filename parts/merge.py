#!/usr/bin/env python3
"""Merge parts/ into the library: voxel parts after voxel.c's core, hfvis.c parts at the end of
hfvis.c, declarations before the closing extern-C block of hfvis.h, tests into test/, fuzz
targets into test/fuzz/. Usage: python3 parts/merge.py [part ...] (default: all present)."""
import os, sys, shutil, re
os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
VOX = ['mesh', 'raster', 'bvh', 'vox', 'cons', 'iv', 'vf', 'volgi']
HF = ['gi2']
FUZZ = {'mesh': 'obj', 'cons': 'binvox'}
want = sys.argv[1:] or [p for p in VOX + HF if os.path.exists('parts/%s.c' % p)]
def read(p): return open(p).read()
def write(p, s): open(p, 'w').write(s)
vox = read('voxel.c'); hf = read('hfvis.c'); hdr = read('hfvis.h')
tail_at = hdr.rindex('#ifdef __cplusplus')
decls = ''
for p in VOX + HF:
    if p not in want: continue
    code = read('parts/%s.c' % p).rstrip() + '\n'
    if p in VOX: vox = vox.rstrip() + '\n\n' + code
    else: hf = hf.rstrip() + '\n\n' + code
    if os.path.exists('parts/%s_decl.h' % p): decls += read('parts/%s_decl.h' % p).rstrip() + '\n\n'
    if os.path.exists('parts/test_%s.c' % p): shutil.copy('parts/test_%s.c' % p, 'test/test_%s.c' % p)
    if p in FUZZ and os.path.exists('parts/fuzz_%s.c' % p):
        shutil.copy('parts/fuzz_%s.c' % p, 'test/fuzz/fuzz_%s.c' % FUZZ[p])
        sd = 'parts/fuzz_seeds_%s' % p
        if os.path.isdir(sd):
            dst = 'test/fuzz/seeds/%s' % FUZZ[p]
            shutil.rmtree(dst, ignore_errors=True); shutil.copytree(sd, dst)
hdr = hdr[:tail_at] + decls + hdr[tail_at:]
write('voxel.c', vox); write('hfvis.c', hf); write('hfvis.h', hdr)
print('merged:', ' '.join(p for p in VOX + HF if p in want))
