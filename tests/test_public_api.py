"""Every public name imports, and ``monitor.certify`` works both as function and package."""

import importlib
import inspect

import pytest

import monitor


@pytest.mark.parametrize("name", [n for n in monitor.__all__ if n != "__version__"])
def test_public_name_imports(name):
    """Each public name resolves to the class or function of that name defined in the package
    (``certify`` and ``rollouts`` are callable submodules: module and function at once)."""
    value = getattr(monitor, name)
    if inspect.ismodule(value):
        assert callable(value) and value.__name__ == f"monitor.{name}", value
    else:
        assert inspect.isclass(value) or inspect.isfunction(value), (name, type(value))
        assert value.__name__ == name
        assert value.__module__.split(".")[0] == "monitor", value.__module__
    namespace: dict = {}
    exec(f"from monitor import {name}", namespace)  # the form users write
    assert namespace[name] is value


def test_all_lists_each_name_once_and_star_import_works():
    assert len(set(monitor.__all__)) == len(monitor.__all__)
    assert isinstance(monitor.__version__, str) and monitor.__version__.count(".") >= 1
    namespace: dict = {}
    exec("from monitor import *", namespace)
    assert set(monitor.__all__) <= set(namespace)
    with pytest.raises(AttributeError):
        monitor.NoSuchName  # noqa: B018


def test_certify_is_callable_after_submodule_import(tmp_path):
    importlib.import_module("monitor.certify.certificate")
    importlib.import_module("monitor.certify.engine")
    assert callable(monitor.certify)
    from monitor.certify import certify
    from monitor.certify.engine import certify as engine_certify

    assert certify is engine_certify
    with pytest.raises(monitor.InvalidInputError):
        monitor.certify(None, None, epsilon=-1.0)


def test_from_monitor_import_certify_does_not_shadow_the_subpackage():
    """Regression: ``from monitor import certify`` bound the bare function to ``monitor.certify``,
    so a later ``import monitor.certify.engine as e`` failed (a test file that did so errored at
    collection when run after one that imported ``certify`` first). Fresh interpreter: import order."""
    import subprocess
    import sys

    code = ("from monitor import certify\n"
            "import monitor.certify.engine as engine\n"
            "import monitor\n"
            "assert callable(certify) and monitor.certify is certify\n"
            "assert engine.certify.__module__ == 'monitor.certify.engine'\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
