"""Helpers shared by gaitsim's data-preparation scripts (standard library only).

- PrepError: a reportable input problem (file and reason); scripts print it as
  "SCRIPT: FILE: reason" and exit 1.
- write_atomic: write text to a temporary file in the target's folder, then rename over the
  target, so a crash never leaves half a file and an earlier file stays until the new one is whole.
"""
import os
import tempfile


class PrepError(Exception):
    """A reportable input problem: file and reason."""

    def __init__(self, file, reason):
        super().__init__(f"{file}: {reason}")
        self.file = file
        self.reason = reason


def write_atomic(path, text):
    """Write text to a temporary file in the same folder (created if missing), then rename over
    path. The file gets the usual 0666 & ~umask mode."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=folder)
    try:
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
