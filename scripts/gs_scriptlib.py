"""Helpers shared by gaitsim's data-preparation scripts (standard library only).

- PrepError: a reportable input problem (file and reason); scripts print it as
  "SCRIPT: FILE: reason" and exit 1.
- write_atomic: write text (or bytes) to a temporary file in the target's folder, then rename
  over the target, so a crash never leaves half a file and an earlier file stays until the new one
  is whole.
- read_json: a JSON object file (summary.json, trial.json) as a dict.
- read_storage: an OpenSim storage file (.sto/.mot: header lines, endheader, a tab-separated label
  line, numeric rows) as (header lines, labels, rows).
"""
import json
import os
import tempfile


class PrepError(Exception):
    """A reportable input problem: file and reason."""

    def __init__(self, file, reason):
        super().__init__(f"{file}: {reason}")
        self.file = file
        self.reason = reason


def write_atomic(path, text):
    """Write text (str, as UTF-8) or bytes to a temporary file in the same folder (created if
    missing), then rename over path. The file gets the usual 0666 & ~umask mode."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=folder)
    try:
        if isinstance(text, bytes):
            with os.fdopen(fd, "wb") as f:
                f.write(text)
        else:
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read_json(path):
    """The JSON object in path (a dict). Raises PrepError for a missing or unreadable file, text
    that is not JSON, or JSON that is not an object."""
    try:
        with open(path, encoding="utf-8") as f:
            obj = json.load(f)
    except FileNotFoundError:
        raise PrepError(path, "file not found")
    except json.JSONDecodeError as e:
        raise PrepError(path, f"not JSON ({e.msg}, line {e.lineno})")
    except OSError as e:
        raise PrepError(path, e.strerror or "cannot read")
    if not isinstance(obj, dict):
        raise PrepError(path, "not a JSON object")
    return obj


def read_storage(path):
    """(header lines, labels, rows) of an OpenSim storage file: the lines before "endheader",
    the column labels (the line after it; tab-separated, or whitespace without tabs) and the rows
    as lists of floats ("nan" parses, so callers check finiteness of what they use). Raises
    PrepError for a missing or unreadable file, no endheader, no rows, a non-numeric value or a
    row whose length differs from the labels'."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except FileNotFoundError:
        raise PrepError(path, "file not found")
    except OSError as e:
        raise PrepError(path, e.strerror or "cannot read")
    try:
        end = [line.strip() for line in lines].index("endheader")
    except ValueError:
        raise PrepError(path, "no endheader line")
    if end + 1 >= len(lines) or not lines[end + 1].strip():
        raise PrepError(path, "no column labels after endheader")
    head = lines[end + 1].strip()
    labels = head.split("\t") if "\t" in head else head.split()
    rows = []
    for lineno, line in enumerate(lines[end + 2:], end + 3):
        if not line.strip():
            continue
        try:
            row = [float(x) for x in line.split()]
        except ValueError:
            raise PrepError(path, f"line {lineno}: non-numeric value")
        if len(row) != len(labels):
            raise PrepError(path, f"line {lineno}: {len(row)} values, {len(labels)} labels")
        rows.append(row)
    if not rows:
        raise PrepError(path, "no data rows")
    return lines[:end], labels, rows
