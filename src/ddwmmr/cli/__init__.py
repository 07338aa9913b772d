"""Command-line entry points: track, compare, scenarios, bench (``python -m ddwmmr.<tool>``)."""
