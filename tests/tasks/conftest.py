"""The graded checks of the course tasks; the plugin msdlab.course.pytest_plugin runs them."""

import pytest

from msdlab.course.pytest_plugin import hypothesis_profiles


def pytest_configure(config: pytest.Config) -> None:
    hypothesis_profiles(config)  # reproducible property checks: derandomised, no deadline
