"""The fast suite's scheduling on pytest-xdist takes effect (tests/conftest.py, scripts/test.sh).

``--dist loadgroup`` sends the tests of one ``xdist_group`` to one worker, so an expensive module
fixture (a Ray instance, the bench's quick case set) is built once. With pytest 9.2.0 and
pytest-xdist 3.8 the group mark is silently ignored (pytest-dev/pytest-xdist#1386: the worker's
node id suffix no longer takes effect) and every worker builds them again; pyproject pins
pytest < 9.2 for the test extra. Under ``--dist loadgroup`` this test fails if grouping is off.
"""

import pytest


@pytest.mark.xdist_group("scheduling_probe")
def test_xdist_groups_take_effect(request):
    if not getattr(request.config.option, "loadgroup", False):
        pytest.skip("not a pytest-xdist worker under --dist loadgroup")
    assert request.node.nodeid.endswith("@scheduling_probe"), (
        "pytest-xdist ignored the xdist_group mark (pytest-dev/pytest-xdist#1386): "
        "module fixtures are built once per worker; use pytest < 9.2")
