import subprocess, sys, os, time, pathlib
tree = pathlib.Path(sys.argv[1]).resolve(); PY = "/work/main/.venv/bin/python"
env = dict(os.environ, PYTHONPATH=str(tree)); env.pop("NUMBA_CACHE_DIR", None)
k = tree / "monitor/motion/kernel.py"
edit = lambda on: k.write_text(k.read_text().replace("    tol[TOL_QMAG] = qmag + 1000.0  # red team 13 repro edit\n", "    tol[TOL_QMAG] = qmag\n") if not on else k.read_text().replace("    tol[TOL_QMAG] = qmag\n", "    tol[TOL_QMAG] = qmag + 1000.0  # red team 13 repro edit\n"))
probe = str(pathlib.Path(__file__).resolve().parent / "probe.py")
run = lambda: subprocess.run([PY, probe], env=env, capture_output=True, text=True, cwd=tree).stdout.split(" from")[0]
edit(False); print("before edit:", run())
p1 = subprocess.Popen([PY, "-c", "import monitor.motion.pack, sys; print('ready', flush=True); sys.stdin.readline(); exec(open(%r).read())" % probe],
                      env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=tree)
assert p1.stdout.readline().strip() == "ready"
time.sleep(1.1); edit(True)
subprocess.run([PY, "-c", "import monitor.motion.pack"], env=env, check=True, cwd=tree)  # P2 purges
print("old process P1:", p1.communicate("go\n")[0].split(" from")[0])
print("later process P3 (source says 1000.3):", run())
edit(False)
