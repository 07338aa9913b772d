"""``python -m ddwmmr``: the command-line tools, one line each."""

from __future__ import annotations

import shlex
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


def _not_a_tool_call(arguments: list[str]) -> str:
    """Why ``python -m ddwmmr ARGUMENTS`` runs nothing, and the command that would: a
    tool's name as the first argument (``python -m ddwmmr track ...``) is the right tool
    in the wrong form, so the line gives the form with the user's own arguments."""
    names = [module.removeprefix("ddwmmr.") for module, _, _ in TOOLS]
    if arguments[0] in names:
        call = shlex.join(["python", "-m", "ddwmmr." + arguments[0], *arguments[1:]])
        return f"the tools are modules of their own, not subcommands: run {call}"
    return f"no tool {arguments[0]!r}; run python -m ddwmmr.<tool> ({', '.join(names)})"


def main(argv: list[str] | None = None) -> int:
    """Print the tools (or, for --version, the version); any other argument than --help
    and --version is an error (status 2)."""
    arguments = sys.argv[1:] if argv is None else argv
    if arguments == ["--version"]:
        from ddwmmr.outputs import package_version

        print(f"ddwmmr {package_version()}")
        return 0
    if arguments and arguments[0] not in ("-h", "--help"):
        print(f"python -m ddwmmr: error: {_not_a_tool_call(arguments)}", file=sys.stderr)
        return 2
    print(usage())
    return 0


if __name__ == "__main__":
    sys.exit(main())
