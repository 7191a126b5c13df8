import json,sys,math,glob,os
det_dir,gt_dir=sys.argv[1],sys.argv[2]
groups={'jaw':range(0,17),'brows':range(17,27),'nose':range(27,36),'eyes':range(36,48),'mouth':range(48,68),'all':range(0,68),'27-67':range(27,68)}
acc={g:[0,0,0,0] for g in groups}  # sum err, sum dx, sum dy, n
for f in sorted(glob.glob(det_dir+'/frame_*.landmarks.json')):
  d=json.load(open(f))['points_px']; g=json.load(open(os.path.join(gt_dir,os.path.basename(f))))['points_px']
  for name,r in groups.items():
    for i in r:
      dx=d[i][0]-g[i][0]; dy=d[i][1]-g[i][1]
      a=acc[name]; a[0]+=math.hypot(dx,dy); a[1]+=dx; a[2]+=dy; a[3]+=1
for name,a in acc.items():
  print(f"{name:6s} mean {a[0]/a[3]:.2f} px  bias ({a[1]/a[3]:+.2f}, {a[2]/a[3]:+.2f}) px  n={a[3]}")
