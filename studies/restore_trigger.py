"""Whether the restoring re-fit would be tried on the records of a diagnosis evaluation (docs/diagnose.md, the
restoring re-fit).

    python studies/restore_trigger.py [docs/diagnose_eval_issue25_full.json ...]

The re-fit is tried after the last round where, in displacement control, the model's gap on a channel exceeds
the nominal model's by more than ``joint.RESTORE_MIN`` (``joint.worse_than_nominal``).  For each evaluation JSON
of ``evaluation/diagnose_eval/evaluate.py`` (its records' ``gap_before``, the nominal model's, and
``gap_after``, the final model's, made by code before the rule or after it): the records on which it would be
tried and the largest excess of a final gap over its nominal's, as a share of the nominal's.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    from servohydraulics.diagnosis.joint import RESTORE_MIN, worse_than_nominal

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("json", nargs="*", default=[str(ROOT / "docs" / "diagnose_eval_issue25_full.json")])
    a = p.parse_args()
    for name in a.json:
        path = Path(name)
        if not path.exists():
            p.error(f"{path} is absent: an evaluation JSON of evaluation/diagnose_eval/evaluate.py")
        records = json.loads(path.read_text())["records"]
        tried, excess = [], []
        for r in records:
            g0, g1 = r["gap_before"], r["gap_after"]
            mode = r.get("mode") or "displacement"  # the JSONs do not say: the rule's own mode, the conservative one
            if worse_than_nominal(g1, g0, mode):
                tried.append(r["id"])
            excess.append(max((g1[c] / g0[c] - 1.0 for c in g0 if g0[c] > 0), default=0.0))
        top = max(excess) if excess else 0.0
        print(f"{path}: {len(records)} records; the restoring re-fit would be tried on {len(tried)}"
              + (f" ({', '.join(tried)})" if tried else "")
              + f"; the largest excess of a final gap over its nominal's: {100 * top:.3g} % "
              f"(the rule's threshold {100 * RESTORE_MIN:g} %)")


if __name__ == "__main__":
    main()
