"""Reading a large CSV of numbers fast: pandas' C parser, when pandas is installed.

numpy.loadtxt parses about 0.6 million values a second here (a million-sample log of 29 columns:
20-40 s); pandas.read_csv (its C engine, `symdyn[ident]` installs pandas) reads the same file
several times faster. Its values are the doubles Python's float gives for the plain decimal
syntax ([+-]digits[.digits][(e|E)[+-]digits], spaces around it, CRLF line ends, blank lines
skipped; tests/test_csv_read.py checks every magnitude written as "%.17g", subnormals included).
Anything else (a value that is not finite, another count of values on a line, text pandas does
not read as a number) makes `parse_rows` return None, and the caller reads the file the slow
way, which names the line and column of the problem or reads what Python reads (1_000). Without
pandas it returns None too, and numpy.loadtxt reads the file.
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["parse_rows"]


def parse_rows(path: str | os.PathLike, skip: int, width: int) -> np.ndarray | None:
    """The values of the file's lines after the first `skip` as a (rows, width) float64 array, or
    None (module docstring)."""
    try:
        import pandas as pd
    except ImportError:
        return None
    try:
        frame = pd.read_csv(
            path,
            header=None,
            skiprows=skip,
            names=list(range(width)),
            na_filter=False,  # an empty field is an error, not NaN
            skip_blank_lines=True,
            engine="c",
        )
    except pd.errors.EmptyDataError:  # no line after the header
        return np.empty((0, width))
    except (ValueError, TypeError, IndexError, OverflowError, UnicodeDecodeError):
        return None  # pandas.errors.ParserError is a ValueError
    if frame.shape == (0, width):
        return np.empty((0, width))
    if frame.shape[1] != width or not all(pd.api.types.is_numeric_dtype(t) for t in frame.dtypes):
        return None  # a column of text: some value is not a number
    values = np.ascontiguousarray(frame.to_numpy(dtype=np.float64))
    return values if np.all(np.isfinite(values)) else None
