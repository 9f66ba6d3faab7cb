#!/usr/bin/python3
"""The include rule of docs/ARCHITECTURE.md §2 (issue 22 item 3): each library layer
includes only the project folders its row of the table names, and every layer may
include daemon/core/errors.h, the typed errors. The table, bottom up, as this check
holds it (keep the two in step):

  errors   daemon/core/errors.h      the standard library only
  text     drivers/text              nothing of the project
  maths    daemon/core               daemon/core
  DBC      daemon/dbc                daemon/dbc
  drivers  drivers/...               drivers
  decode   daemon/decode             maths, DBC, drivers/can_frame.h, drivers/csv, drivers/text
  service  daemon/service            maths, text

app (daemon/app) and tools/ may include every layer, so they are not checked here.
An include is "#include "daemon/..."" (or drivers/, tools/, proto/): spelled from the
repository root, as §2 says. Usage: check_layers.py SOURCE_DIR. Python 3 standard
library only.
"""
import os
import re
import sys

ERRORS = "daemon/core/errors.h"
# (the including file's path prefix, the include prefixes it may use); first match wins.
RULES = [
    (ERRORS, ()),
    ("drivers/text/", ("drivers/text/",)),
    ("daemon/core/", ("daemon/core/",)),
    ("daemon/dbc/", ("daemon/dbc/",)),
    ("drivers/", ("drivers/",)),
    ("daemon/decode/", ("daemon/decode/", "daemon/core/", "daemon/dbc/", "drivers/can_frame.h", "drivers/csv/",
                        "drivers/text/")),
    ("daemon/service/", ("daemon/service/", "daemon/core/", "drivers/text/")),
]
PROJECT = ("daemon/", "drivers/", "tools/", "proto/")
INCLUDE = re.compile(r'\s*#\s*include\s+"([^"]+)"')


def allowed_for(path):
    return next((allowed for prefix, allowed in RULES if path.startswith(prefix)), None)


def violations(src):
    """(the problems found, the number of project includes checked)."""
    problems, checked = [], 0
    for top in ("daemon", "drivers"):
        for folder, _, files in os.walk(os.path.join(src, top)):
            for name in sorted(files):
                path = os.path.relpath(os.path.join(folder, name), src)
                allowed = allowed_for(path)
                if allowed is None or not name.endswith((".h", ".cpp")):
                    continue
                with open(os.path.join(src, path), errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if m is None or not m.group(1).startswith(PROJECT):
                            continue
                        included = m.group(1)
                        checked += 1
                        if included == ERRORS and path != ERRORS:
                            continue
                        if not included.startswith(allowed):
                            problems.append(f"{path}:{number}: includes {included}, which its layer may not "
                                            f"(docs/ARCHITECTURE.md §2)")
    return problems, checked


def main():
    src = sys.argv[1]
    problems, checked = violations(src)
    for p in problems:
        print(p)
    # The check must see the tree: a wrong SOURCE_DIR would pass with nothing checked.
    if checked < 100:
        print(f"only {checked} project includes found under {src}/daemon and {src}/drivers: wrong folder?")
        return 1
    # A control: the rule refuses what it should (a driver including the service layer).
    driver = allowed_for("drivers/candump/x.h")
    if driver is None or "daemon/service/x.h".startswith(driver):
        print("the rule table lets a driver include daemon/service")
        return 1
    print(f"{checked} project includes checked, {len(problems)} against the layer rule")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
