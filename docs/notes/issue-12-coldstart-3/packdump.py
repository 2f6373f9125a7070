"""Dump every GeomPack field (via attribute names) of several scenes for an old/new comparison."""
import pickle, sys, numpy as np, mujoco, monitor
from monitor._paths import scene_path
from monitor.certify.packed import pack_scene, pack_shapes
from monitor.geometry.shapes import ConvexShape
F = ["verts","vstart","edges","estart","normals","nstart","kind","radius","offset","dpad","approx","body","mpts","mw","mstart","rho_max","curve","cparam","cframe","ccenter","bcenter","brad"]
out = {}
import glob, os
for name in ["arm", "tunnel"] + [os.path.basename(p)[:-4] for p in sorted(glob.glob(str(scene_path("arm").parent / "*.xml")))]:
    try:
        model = mujoco.MjModel.from_xml_path(str(scene_path(name)))
        sc = monitor.Scene.from_model(model)
        gp = pack_scene(sc).geoms
    except Exception as e:
        out[name] = repr(e); continue
    out[name] = {f: (np.asarray(getattr(gp, f)).dtype.str, np.asarray(getattr(gp, f)).shape, np.asarray(getattr(gp, f)).tobytes()) for f in F}
gp = pack_shapes([], [])
out["empty"] = {f: (np.asarray(getattr(gp, f)).dtype.str, np.asarray(getattr(gp, f)).shape, np.asarray(getattr(gp, f)).tobytes()) for f in F}
pickle.dump(out, open(sys.argv[1], "wb"))
print(len(out), [k for k, v in out.items() if isinstance(v, str)])
