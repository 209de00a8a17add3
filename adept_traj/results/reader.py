"""Reading the files of a result folder, with errors that name the file.

- ``read_text(path)``: the UTF-8 text of a file (missing, unreadable or not UTF-8:
  :class:`~adept_traj.errors.ResultFormatError`).
- ``open_json(path)``: the top :class:`~adept_traj.schema.Node` of a JSON file, whose
  accessors raise :class:`~adept_traj.errors.ResultFormatError` naming the file and the
  dotted field path (``front[3].x``).

Used by :mod:`~adept_traj.results.json_codec` and :mod:`~adept_traj.results.csv_codec`.
"""

from __future__ import annotations

from pathlib import Path

from adept_traj.errors import ResultFormatError
from adept_traj.files import read_bytes_bounded
from adept_traj.schema import Node

__all__ = [
    "open_json",
    "read_text",
]


def open_json(path: Path) -> Node:
    """The top node of a JSON file of a result folder (NaN and Infinity refused).

    Parameters
    ----------
    path:
        The file.

    Returns
    -------
    Node
        Its accessors raise :class:`~adept_traj.errors.ResultFormatError` naming the file
        and the field.
    """
    return Node.from_json(read_text(path), path, ResultFormatError)


def read_text(path: Path) -> str:
    """The UTF-8 text of the file ``path`` of the result folder, at most
    :data:`~adept_traj.files.MAX_FILE_BYTES` (:func:`open_json` parses a JSON one).

    Raises
    ------
    ResultFormatError
        Missing, unreadable, too large or not UTF-8.
    """

    def refuse(message: str) -> ResultFormatError:
        return ResultFormatError(path, None, message.removeprefix(f"{path}: "))

    def missing(_message: str) -> ResultFormatError:
        return ResultFormatError(path, None, "missing file")

    raw = read_bytes_bounded(path, refuse, not_found=missing, what="result file")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ResultFormatError(path, None, f"not UTF-8 text ({exc.reason})") from None
