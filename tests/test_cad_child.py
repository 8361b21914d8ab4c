"""The reader child process: answers, errors, warnings and a crash, with stand-in readers
(module-level functions of this file, which the child imports by name)."""

import os
import signal
import sys
import warnings

import numpy as np
import pytest

from splinedeform.cad_child import read_in_child
from splinedeform.errors import InputError, InputWarning


def answer(path, n):
    warnings.warn(f"{path}: a note from the child", stacklevel=2)
    return {"pid": os.getpid(), "points": np.arange(n, dtype=float)}


def refuse(path):
    raise InputError(f"{path}: refused by the reader")


def fail(path):
    return {}["missing key"]


def crash(path):
    os.kill(os.getpid(), signal.SIGSEGV)


def test_answer_and_warnings_come_back_from_another_process(tmp_path):
    with pytest.warns(InputWarning, match="part.igs: a note from the child"):
        got = read_in_child(answer, tmp_path / "part.igs", 4)
    assert got["pid"] != os.getpid()
    # plain arrays through a pickle: the same numbers, exactly (no arithmetic on the way)
    assert got["points"].dtype == np.float64 and got["points"].tolist() == [0.0, 1.0, 2.0, 3.0]
    with pytest.warns(InputWarning):
        again = read_in_child(answer, tmp_path / "part.igs", 1)
    assert again["pid"] == got["pid"]          # one child, kept for the next read


def test_errors_and_failures_of_the_reader_name_the_file(tmp_path):
    with pytest.raises(InputError, match="^part.step: refused by the reader$"):
        read_in_child(refuse, "part.step")
    with pytest.raises(InputError, match=r"part.step: the reader failed on this file "
                                         r"\(KeyError: 'missing key' in fail\)"):
        read_in_child(fail, "part.step")


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_a_crash_of_the_reader_is_an_error_and_the_next_read_works(tmp_path):
    with pytest.warns(InputWarning):
        first = read_in_child(answer, "a.3dm", 1)["pid"]
    with pytest.raises(InputError, match=r"bad.3dm: the CAD reader crashed reading this file "
                                         r"\(signal SIGSEGV\); the file is probably malformed"):
        read_in_child(crash, "bad.3dm")
    with pytest.warns(InputWarning):
        assert read_in_child(answer, "a.3dm", 1)["pid"] not in (first, os.getpid())
