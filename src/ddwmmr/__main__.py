"""``python -m ddwmmr``: the command-line tools, one line each."""

from __future__ import annotations

import sys

#: (module run with ``python -m``, console script, what it does).
TOOLS = (
    ("ddwmmr.track", "ddwmmr-track", "one method on one trajectory: time series, figures"),
    ("ddwmmr.compare", "ddwmmr-compare", "every method on the same trajectories: HTML report"),
    ("ddwmmr.scenarios", "ddwmmr-scenarios", "the thesis's 100-scenario waypoint benchmark"),
    ("ddwmmr.bench", "ddwmmr-bench", "per-step latency and throughput of the controllers"),
    ("ddwmmr.bounds", "ddwmmr-bounds", "the scenarios' minimum time, bracketed from both sides"),
    ("ddwmmr.gui", "ddwmmr-gui", "interactive simulator window (headless: --snapshot)"),
)


def usage() -> str:
    """The list of tools printed by ``python -m ddwmmr``."""
    width = max(len(module) for module, _, _ in TOOLS) + len("python -m ")
    script_width = max(len(script) for _, script, _ in TOOLS)
    lines = [
        "ddwmmr command-line tools (each answers --help and --version; console script in the "
        "middle):"
    ]
    for module, script, text in TOOLS:
        lines.append(f"  {'python -m ' + module:<{width}}  {script:<{script_width}}  {text}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Print the tools (or, for --version, the version); any other argument than --help
    and --version is an error (status 2)."""
    arguments = sys.argv[1:] if argv is None else argv
    if arguments == ["--version"]:
        from ddwmmr.outputs import package_version

        print(f"ddwmmr {package_version()}")
        return 0
    if arguments and arguments[0] not in ("-h", "--help"):
        print(
            f"python -m ddwmmr: error: no tool {arguments[0]!r}; run python -m ddwmmr.<tool> "
            "(track, compare, scenarios, bench, bounds, gui)",
            file=sys.stderr,
        )
        return 2
    print(usage())
    return 0


if __name__ == "__main__":
    sys.exit(main())
