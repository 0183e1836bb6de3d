"""Shared pytest settings: hypothesis profiles (``HYPOTHESIS_PROFILE=thorough`` for more)."""

import os

from hypothesis import HealthCheck, settings

settings.register_profile(
    "default", max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile("thorough", max_examples=2000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


def pytest_addoption(parser):
    parser.addoption(
        "--regenerate-goldens",
        action="store_true",
        help="rewrite the golden images from the current renders (same as "
        "PHONG_EXPLORER_REGENERATE_GOLDENS=1); review the diff before committing",
    )


def pytest_configure(config):
    if config.getoption("--regenerate-goldens"):
        os.environ["PHONG_EXPLORER_REGENERATE_GOLDENS"] = "1"
