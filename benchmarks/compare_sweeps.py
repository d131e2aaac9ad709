"""Two sweeps' optima side by side: for every gait file of the first folder, the solver's value
in both and its relative change, the starts at the best in both; then how many are equal (to
``EQUAL``), lower and higher. What a change of the optimizer is checked with: a sweep before
it and one after, run the same way.

    python benchmarks/compare_sweeps.py BEFORE_FOLDER AFTER_FOLDER [--tolerance 1e-6]

Exit status 1 when an optimum of the second is higher than the first's by more than the
tolerance (relative; default ``EQUAL``).
"""

import argparse
import sys
from pathlib import Path

from biped.records import gait_file

EQUAL = 1e-9  # relative


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument(
        "--tolerance", type=float, default=EQUAL, help=f"relative, >= 0 (default {EQUAL:g})"
    )
    args = parser.parse_args()
    if not args.tolerance >= 0:
        parser.error(f"--tolerance {args.tolerance}: allowed a number >= 0")
    tolerance = args.tolerance
    changes = []
    for path in sorted(args.before.glob("*-*-*.json")):
        other = args.after / path.name
        if not other.exists():
            print(f"{path.name}: not in {args.after}", file=sys.stderr)
            return 2
        a, b = gait_file.read(path).optimizer, gait_file.read(other).optimizer
        change = (b.value - a.value) / abs(a.value)
        changes.append(change)
        mark = "" if abs(change) <= tolerance else ("  lower" if change < 0 else "  HIGHER")
        print(
            f"{path.name:32} {a.value:.10g} {b.value:.10g} {change:+.2e}  starts at best "
            f"{a.starts_at_best} -> {b.starts_at_best}{mark}"
        )
    equal = sum(abs(c) <= tolerance for c in changes)
    lower = sum(c < -tolerance for c in changes)
    higher = sum(c > tolerance for c in changes)
    print(f"{len(changes)} optima: {equal} equal to {tolerance:g}, {lower} lower, {higher} higher")
    return 1 if higher else 0


if __name__ == "__main__":
    sys.exit(main())
