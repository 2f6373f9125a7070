"""Run the new pack-check tests against weaker designs: each must FAIL some test."""
import sys, pytest
from monitor.certify import kernels as K
design = sys.argv[1]
seen = {}
def per_structure(traj, mp):          # verify once per model structure, trust afterwards
    k = getattr(getattr(traj, "_st", None), "key", None)
    if k in seen: return True
    seen[k] = K._poses_match(traj, mp); return seen[k]
def no_data(traj, mp):                # tree check but no per-plan data check
    from monitor.motion.pack import static_key
    key = (traj._st.key, static_key(mp))
    return K._tree_verified(traj, mp, key)
def first_only(traj, mp):            # commit 5383c5c: full check on the key's first plan only
    from monitor.motion.pack import plan_data_agrees, static_key
    key = (traj._st.key, static_key(mp))
    first = key not in K._VERIFIED_TREES
    if not K._tree_verified(traj, mp, key) or not plan_data_agrees(traj, mp):
        return False
    return K._poses_match(traj, mp) if first else True
K._pack_agrees = {"per_structure": per_structure, "no_data": no_data, "first_only": first_only}[design]
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", "tests/test_window_kernel.py", "-k",
                      "corrupted or in_place or per_plan or first_plan"]))
