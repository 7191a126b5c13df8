#!/usr/bin/env python3
"""Compares two `gvkit facemap clean` output folders frame by frame: landmark files identical
byte for byte, vertices (position + colour) in common, oriented faces in common (as corner
positions, so a different vertex order compares equal), and the surface area ratio.

Usage: compare_faces.py FACES_A FACES_B"""
import filecmp, glob, os, struct, sys

def read_ply(path):
    with open(path, 'rb') as f:
        header = b''
        while not header.endswith(b'end_header\n'):
            header += f.readline()
        lines = header.decode().split('\n')
        nv = int([l for l in lines if l.startswith('element vertex')][0].split()[2])
        nf = int([l for l in lines if l.startswith('element face')][0].split()[2])
        props = sum(1 for l in lines if l.startswith('property float'))
        data = f.read(nv * props * 4)
        verts = [struct.unpack_from('<%df' % props, data, i * props * 4) for i in range(nv)]
        faces = []
        for _ in range(nf):
            n = f.read(1)[0]
            faces.append(struct.unpack('<%di' % n, f.read(4 * n)))
    return verts, faces

def area(verts, faces):
    s = 0.0
    for a, b, c in faces:
        p, q, r = verts[a][:3], verts[b][:3], verts[c][:3]
        u = [q[i] - p[i] for i in range(3)]; v = [r[i] - p[i] for i in range(3)]
        x = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        s += 0.5 * (x[0] ** 2 + x[1] ** 2 + x[2] ** 2) ** 0.5
    return s

def canon(face, verts):
    pts = [verts[i] for i in face]
    k = pts.index(min(pts))
    return tuple(pts[k:] + pts[:k])

if len(sys.argv) != 3:
    sys.exit(__doc__)
a_dir, b_dir = sys.argv[1], sys.argv[2]
frames = sorted(os.path.basename(p) for p in glob.glob(os.path.join(a_dir, 'frame_*.ply')))
tot = dict(frames=0, lm_same=0, va=0, vb=0, vcommon=0, fa=0, fb=0, fcommon=0)
ratios = []
for name in frames:
    other = os.path.join(b_dir, name)
    if not os.path.exists(other):
        print(name, 'missing in', b_dir); continue
    tot['frames'] += 1
    lm = name.replace('.ply', '.landmarks.json')
    tot['lm_same'] += filecmp.cmp(os.path.join(a_dir, lm), os.path.join(b_dir, lm), shallow=False)
    va, fa = read_ply(os.path.join(a_dir, name)); vb, fb = read_ply(other)
    sa, sb = set(va), set(vb)
    tot['va'] += len(va); tot['vb'] += len(vb); tot['vcommon'] += len(sa & sb)
    ca = set(canon(f, va) for f in fa); cb = set(canon(f, vb) for f in fb)
    tot['fa'] += len(fa); tot['fb'] += len(fb); tot['fcommon'] += len(ca & cb)
    ratios.append(area(va, fa) / area(vb, fb))
print('frames compared %d, landmark files identical %d' % (tot['frames'], tot['lm_same']))
print('vertices %d / %d, in common %d (%.2f %% of the second)' % (tot['va'], tot['vb'], tot['vcommon'], 100.0 * tot['vcommon'] / tot['vb']))
print('faces %d / %d, in common %d (%.2f %% of the second)' % (tot['fa'], tot['fb'], tot['fcommon'], 100.0 * tot['fcommon'] / tot['fb']))
print('area ratio first / second: mean %.4f, min %.4f, max %.4f' % (sum(ratios) / len(ratios), min(ratios), max(ratios)))
