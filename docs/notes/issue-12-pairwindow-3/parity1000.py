import json, os, sys
tree = os.environ["PYTHONPATH"]
sys.path.insert(0, os.path.join(tree, "tests"))
import test_accuracy as TA
out = []
for i in range(TA.N_CASES):
    scene, plan, margin, cat, desc = TA.make_case(10_000 + i)
    cert = TA.certify(scene, plan, margin=margin, epsilon=TA.EPS, method="toleranced")
    out.append([str(cert.verdict), repr(float(cert.clearance)), int(cert.stats.get("tests", -1)),
                None if cert.earliest_time is None else repr(float(cert.earliest_time)), cat])
json.dump(out, open(sys.argv[1], "w"))
print(len(out), "cases")
