"""Loader of the captured rare calls: scene, plan, args, kwargs; replays certify."""
import pickle, sys
def load(path="/tmp/armrare/caps.pkl"):
    caps = pickle.load(open(path, "rb"))
    return [(c, *pickle.loads(c["blob"])) for c in caps]
