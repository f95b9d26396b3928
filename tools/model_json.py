"""What the model generators in tools/ share: writing a model document as femdyn's bundled JSON
files are written (two-space indents, each list of numbers on one line)."""
import json
import os
import re

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def dump(doc):
    """JSON with two-space indents, each list of numbers on one line."""
    text = json.dumps(doc, indent=2, ensure_ascii=False)
    return re.sub(r"\[\s*([-0-9.e,\s]+?)\s*\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]",
                  text) + "\n"


def write(doc, out=None, default_name=None):
    """Writes doc to `out`, or to models/<default_name> of this checkout when out is None."""
    path = out if out else os.path.join(ROOT, "models", default_name)
    with open(path, "w") as f:
        f.write(dump(doc))
