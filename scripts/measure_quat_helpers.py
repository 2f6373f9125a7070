"""Quaternion helpers: hand-written vs scipy Rotation / mujoco.mju_* (timings, max differences).

Usage: PYTHONPATH=. python scripts/measure_quat_helpers.py   (docs/notes/issue-16.md, "Leftovers (h16b)")
"""
import timeit, numpy as np, mujoco
from scipy.spatial.transform import Rotation, Slerp
from monitor.motion import _kinematics as K
from monitor.certify.packed import _quat_mat
from monitor.bench.cases import slerp_matrices
rng = np.random.default_rng(0)
def med(f, n):
    return np.median(timeit.repeat(f, number=n, repeat=7)) / n * 1e6
for N in (1, 8, 1000):
    q = rng.normal(size=(N, 4)); q /= np.linalg.norm(q, axis=1, keepdims=True)
    a = med(lambda: K.quat_to_mat(q), 200); b = med(lambda: Rotation.from_quat(q, scalar_first=True).as_matrix(), 200)
    def mj():
        R = np.empty((N, 9))
        for i in range(N): mujoco.mju_quat2Mat(R[i], q[i])
    c = med(mj, 50)
    e1 = np.abs(K.quat_to_mat(q) - Rotation.from_quat(q, scalar_first=True).as_matrix()).max()
    print(f"quat_to_mat N={N}: hand {a:.1f} us, scipy {b:.1f} us ({b/a:.2f}x), mju loop {c:.1f} us ({c/a:.2f}x), max diff {e1:.1e}")
    a = med(lambda: K.quat_mul(q, q[::-1]), 200)
    b = med(lambda: (Rotation.from_quat(q, scalar_first=True)*Rotation.from_quat(q[::-1], scalar_first=True)).as_quat(scalar_first=True), 200)
    print(f"quat_mul N={N}: hand {a:.1f} us, scipy {b:.1f} us ({b/a:.2f}x)")
    v = rng.normal(size=(N, 3))
    a = med(lambda: K.quat_rotate(q, v), 200); b = med(lambda: Rotation.from_quat(q, scalar_first=True).apply(v), 200)
    print(f"quat_rotate N={N}: hand {a:.1f} us, scipy {b:.1f} us ({b/a:.2f}x)")
    a = med(lambda: K.quat_angle(q, q[::-1]), 200)
    b = med(lambda: (Rotation.from_quat(q, scalar_first=True)*Rotation.from_quat(q[::-1], scalar_first=True).inv()).magnitude(), 200)
    print(f"quat_angle N={N}: hand {a:.1f} us, scipy {b:.1f} us ({b/a:.2f}x)")
    ang = rng.uniform(-3, 3, N); ax = np.array([0, 0.6, 0.8])
    a = med(lambda: K.axis_angle_mat(ax, ang), 200); b = med(lambda: Rotation.from_rotvec(ang[:, None] * ax).as_matrix(), 200)
    print(f"axis_angle_mat N={N}: hand {a:.1f} us, scipy {b:.1f} us ({b/a:.2f}x)")
q1 = rng.normal(size=4); q1/=np.linalg.norm(q1)
a = med(lambda: _quat_mat(q1), 500); b = med(lambda: Rotation.from_quat(q1, scalar_first=True).as_matrix(), 500)
R=np.empty(9); c = med(lambda: mujoco.mju_quat2Mat(R, q1), 500)
print(f"packed._quat_mat single: hand {a:.1f} us scipy {b:.1f} mju {c:.1f}; bit-identical to K.quat_to_mat: {np.array_equal(_quat_mat(q1), K.quat_to_mat(q1))}")
mujoco.mju_quat2Mat(R, q1); print("vs mju max diff", np.abs(R.reshape(3,3)-_quat_mat(q1)).max())
rng = np.random.default_rng(1)
worst = 0
for i in range(2000):
    q0 = Rotation.random(random_state=rng).as_quat(scalar_first=True)
    small = i % 3 == 0
    r1 = Rotation.from_rotvec((1e-10 if i % 6 == 0 else 1e-5 if small else 3.0) * rng.normal(size=3)) * Rotation.from_quat(q0, scalar_first=True)
    q1 = r1.as_quat(scalar_first=True)
    if q0 @ q1 < 0: q1 = -q1
    s = np.linspace(0, 1, 41)
    a = slerp_matrices(q0, q1, s)
    b = Slerp([0.0, 1.0], Rotation.from_quat(np.stack([q0, q1]), scalar_first=True))(s).as_matrix()
    worst = max(worst, np.abs(a - b).max())
print("max |hand - scipy Slerp| over 2000 pairs x 41 s:", worst)
q0 = Rotation.random(random_state=rng).as_quat(scalar_first=True); q1 = Rotation.random(random_state=rng).as_quat(scalar_first=True)
if q0@q1<0: q1=-q1
s = np.linspace(0,1,41)
f1 = lambda: slerp_matrices(q0,q1,s); f2 = lambda: Slerp([0.0,1.0], Rotation.from_quat(np.stack([q0,q1]), scalar_first=True))(s).as_matrix()
for f,n in ((f1,"hand"),(f2,"scipy")):
    print(n, np.median(timeit.repeat(f, number=200, repeat=7))/200*1e6, "us")
