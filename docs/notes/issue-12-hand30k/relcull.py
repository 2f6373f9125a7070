"""How many stage-0 survivors relative swept spheres (pair_bound relative=1) would cull: whole window, 8 sub-ranges."""
import sys
import numpy as np
import h30
import monitor.certify.engine as E
import monitor.certify.kernels as KS
from monitor.motion import kernel as KN
kept, W, scene, req = h30.setup(sys.argv[1])
rec, _wk = h30.spy_kernel_calls()
stats = []
for i in range(0, 60, 6):
    p = h30.joint_plan(W, kept[i])
    rec.clear(); E.certify(scene, p, request=req)
    gp, mp, pairs, _, _, _, rest = rec[0]
    info, surv = rest[12], rest[7]
    S = int(info[KS.WI_SURV]); t0, t1 = p.times[0], p.times[-1]
    pws = KN.pair_workspace(mp)
    culled = {1: 0, 8: 0}
    shared = 0
    for k in surv[:S]:
        ga, gb = pairs[k]
        ba, bb = gp.body[ga], gp.body[gb]
        for T in (1, 8):
            ok = True
            for j in range(T):
                ta = t0 + (t1 - t0) * j / T; tb = t0 + (t1 - t0) * (j + 1) / T
                pA, RA, pB, RB = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
                TA, aA, TB, aB = KN.pair_bound(mp, ba, bb, ta, tb, pA, RA, pB, RB, pws, 1)
                cA = RA @ gp.bcenter[ga] + pA; cB = RB @ gp.bcenter[gb] + pB
                levA = np.linalg.norm(gp.bcenter[ga] - mp.ref_points[ba]) + gp.brad[ga]
                levB = np.linalg.norm(gp.bcenter[gb] - mp.ref_points[bb]) + gp.brad[gb]
                chA, chB = 2*np.sin(min(aA, np.pi)/2), 2*np.sin(min(aB, np.pi)/2)
                gap = np.linalg.norm(cA - cB) - gp.brad[ga] - gp.brad[gb] - TA - chA*levA - TB - chB*levB
                if not gap > 1e-9:
                    ok = False; break
            culled[T] += ok
    stats.append((S, culled[1], culled[8]))
print("(survivors, relative-sphere culled over whole window, over 8 sub-ranges):", stats)
