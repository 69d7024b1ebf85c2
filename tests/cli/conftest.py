"""Shared test set-up: plots render off-screen with the Agg backend."""

import matplotlib

matplotlib.use("Agg")
