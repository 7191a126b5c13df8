#!/usr/bin/env python3
"""Landmark errors per group: detected points_px against ground-truth points_px.

Usage: landmark_errors.py DETECTED_DIR TRUTH_DIR
DETECTED_DIR holds frame_NNNNNN.landmarks.json (e.g. the output of `gvkit facemap clean`),
TRUTH_DIR the same names (e.g. a synth session's gt/ folder). Prints, per group (jaw 0-16,
brows 17-26, nose 27-35, eyes 36-47, mouth 48-67, all, 27-67): the mean error (px), the mean
signed offset (dx, dy), and the mean error left after removing each landmark's own mean offset
over the frames (the detection noise; the rest is a constant difference of conventions).
"""
import glob
import json
import math
import os
import sys

GROUPS = {'jaw': range(0, 17), 'brows': range(17, 27), 'nose': range(27, 36),
          'eyes': range(36, 48), 'mouth': range(48, 68), 'all': range(0, 68),
          '27-67': range(27, 68)}


def main():
    detected_dir, truth_dir = sys.argv[1], sys.argv[2]
    errors = []  # per frame: 68 (dx, dy)
    for path in sorted(glob.glob(os.path.join(detected_dir, 'frame_*.landmarks.json'))):
        truth_path = os.path.join(truth_dir, os.path.basename(path))
        if not os.path.exists(truth_path):
            continue
        d = json.load(open(path))['points_px']
        t = json.load(open(truth_path))['points_px']
        errors.append([(d[i][0] - t[i][0], d[i][1] - t[i][1]) for i in range(68)])
    if not errors:
        sys.exit('no frame with both detected and true landmarks')
    n = len(errors)
    bias = [(sum(e[i][0] for e in errors) / n, sum(e[i][1] for e in errors) / n)
            for i in range(68)]
    print(f'{n} frames')
    for name, ids in GROUPS.items():
        count = n * len(ids)
        mean = sum(math.hypot(*e[i]) for e in errors for i in ids) / count
        dx = sum(e[i][0] for e in errors for i in ids) / count
        dy = sum(e[i][1] for e in errors for i in ids) / count
        resid = sum(math.hypot(e[i][0] - bias[i][0], e[i][1] - bias[i][1])
                    for e in errors for i in ids) / count
        print(f'{name:6s} mean {mean:5.2f} px  offset ({dx:+.2f}, {dy:+.2f}) px  '
              f'residual {resid:4.2f} px')


if __name__ == '__main__':
    main()
