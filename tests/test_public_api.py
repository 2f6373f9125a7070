"""Every public name imports, and ``monitor.certify`` works both as function and package."""

import importlib

import pytest

import monitor


@pytest.mark.parametrize("name", [n for n in monitor.__all__ if n != "__version__"])
def test_public_name_imports(name):
    assert getattr(monitor, name) is not None


def test_certify_is_callable_after_submodule_import(tmp_path):
    importlib.import_module("monitor.certify.certificate")
    importlib.import_module("monitor.certify.engine")
    assert callable(monitor.certify)
    from monitor.certify import certify
    from monitor.certify.engine import certify as engine_certify

    assert certify is engine_certify
    with pytest.raises(monitor.InvalidInputError):
        monitor.certify(None, None, epsilon=-1.0)
