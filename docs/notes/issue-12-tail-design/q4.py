"""Q4: the longest braking horizon at which a floor is reachable at all, by arithmetic.

python docs/notes/issue-12-tail-design/q4.py RATIOS_OUT TAILSTATS_OUT FLOOR

RATIOS_OUT: ratios.py's output (horizons 0.05 0.1 0.25 and off); TAILSTATS_OUT: tailstats.py's
output at the default horizon. Per second of braking tail, in units of the ungated step:
  phys = tail physics per tail substep (tailstats, in situ) / timestep / ungated step;
  cert = (joint call - window call) per tail substep (tailstats, isolated) / timestep / ungated.
H_max = the longest horizon with ratio <= FLOOR when
  (i)   only the tail's physics is paid besides the ungated step: 1 + phys * H;
  (ii)  the tail's physics and its certify share are paid: 1 + (phys + cert) * H;
  (iii) the rest of the gate stays as measured: ratio(H) fitted linearly to the interleaved
        ratios at 0.05 / 0.1 / 0.25 s (intercept R0, slope), and, second figure, R0 = the
        brake=False ratio with the same slope.
"none" when even H = 0 is above the floor. Prints "Q4 {...}".
"""
import json, sys

import numpy as np

ra = json.loads(open(sys.argv[1]).read().split("RATIOS ")[1])
ts = json.loads(open(sys.argv[2]).read().split("STATS ")[1])
floor = float(sys.argv[3])
u = ra["ungated_us"]
dt = ts["horizon"] / ts["brake_steps"]
substeps = ts["tail_substeps"]["total"]
phys_sub = ts["us_per_step"]["tail_physics"] * ts["steps"] / substeps
cert_sub = max(ts["certify_isolated_us"]["joint_minus_window_median"], 0.0) / ts["brake_steps"]
phys = phys_sub / dt / u
cert = cert_sub / dt / u
H = np.array([float(h) for h in ("0.05", "0.1", "0.25")])
R = np.array([ra["variants"][h]["ratio"] for h in ("0.05", "0.1", "0.25")])
slope, r0 = np.polyfit(H, R, 1)
off = ra["variants"]["off"]["ratio"]

def hmax(r0_, per_s):
    return None if r0_ > floor or per_s <= 0 else (floor - r0_) / per_s

print("Q4 " + json.dumps({
    "work": ts["work"], "floor": floor, "ungated_us": u, "timestep": dt,
    "tail_physics_us_per_substep": phys_sub, "tail_certify_us_per_substep": cert_sub,
    "x_per_s_of_tail": {"physics": phys, "certify": cert, "fit_slope": slope},
    "ratio_fit_intercept_R0": r0, "ratio_brake_off": off,
    "ratios": dict(zip(("0.05", "0.1", "0.25"), R.tolist())),
    "H_max_s": {"(i) physics only": hmax(1.0, phys), "(ii) physics + tail certify": hmax(1.0, phys + cert),
                "(iii) as measured (fit)": hmax(r0, slope), "(iii') R0 = brake off": hmax(off, slope)}}))
