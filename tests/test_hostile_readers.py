"""Every public reader of the library refuses what is not a regular file, without blocking.

A named pipe without a writer blocks ``open`` forever. Each test puts one where a reader
expects a file and starts a thread that opens the pipe for writing after a few seconds:
should the reader block (the bug), it is released, reads an empty file and the test fails
on the message instead of hanging.
"""
from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest

from splinedeform.errors import InputError

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")


def unblock_after(path: Path, seconds: float = 5.0) -> None:
    """Open the named pipe ``path`` for writing after ``seconds`` (then close it), which
    releases a reader blocked on it."""
    def writer() -> None:
        time.sleep(seconds)
        try:
            os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:
            pass              # no reader waiting: nothing to unblock
    threading.Thread(target=writer, daemon=True).start()


def pipe(tmp_path: Path, name: str) -> Path:
    path = tmp_path / name
    os.mkfifo(path)
    unblock_after(path)
    return path


def _read_cad(path: Path) -> object:
    from splinedeform.cad import read_cad
    return read_cad(path)


def _read_3dm(path: Path) -> object:
    pytest.importorskip("rhino3dm")
    from splinedeform.cad import read_3dm
    return read_3dm(path)


def _read_step(path: Path) -> object:
    from splinedeform.cad_step import read_step
    return read_step(path)


def _read_faces(path: Path) -> object:
    from splinedeform.cad_faces import read_faces
    return read_faces(path)


def _read_control_net(path: Path) -> object:
    from splinedeform.export.nets import read_control_net
    return read_control_net(path)


READERS = [(_read_cad, "part.3dm"), (_read_cad, "part.step"), (_read_cad, "part.igs"),
           (_read_3dm, "part.3dm"), (_read_step, "part.stp"), (_read_step, "part.iges"),
           (_read_faces, "part.3dm"), (_read_faces, "part.step"),
           (_read_control_net, "nets.json"), (_read_control_net, "nets.npz")]


@pytest.mark.parametrize("reader, name", READERS,
                         ids=[f"{r.__name__[1:]}-{n}" for r, n in READERS])
def test_a_named_pipe_given_to_a_reader_is_refused_naming_it(tmp_path, reader, name):
    path = pipe(tmp_path, name)
    with pytest.raises(InputError) as info:
        reader(path)
    assert f"{path}: the " in str(info.value)
    assert "is a named pipe, not a regular file" in str(info.value)


def test_a_folder_given_to_a_cad_reader_is_named_as_a_folder(tmp_path):
    folder = tmp_path / "part.step"
    folder.mkdir()
    with pytest.raises(InputError, match="part.step: the CAD file is a folder"):
        _read_cad(folder)


def test_a_missing_cad_file_is_still_no_such_file(tmp_path):
    with pytest.raises(InputError, match="missing.3dm: no such file"):
        _read_cad(tmp_path / "missing.3dm")


def test_a_named_pipe_as_the_manifest_is_refused_by_the_run_folder(tmp_path):
    from splinedeform.export import claim_folder, manifest_name
    from splinedeform.export.run_folder import incomplete_note, read_manifest

    path = pipe(tmp_path, manifest_name("case"))
    with pytest.raises(InputError) as info:
        read_manifest(path)
    assert "the run manifest is a named pipe, not a regular file" in str(info.value)
    assert "choose another output folder" in str(info.value)
    with pytest.raises(InputError, match="is a named pipe"):
        claim_folder(tmp_path, "case", ["case.obj"])
    assert incomplete_note(tmp_path, "case") is None     # nothing of ours to report


def test_another_scenarios_manifest_as_a_named_pipe_claims_nothing(tmp_path):
    from splinedeform.export import claim_folder, manifest_name

    pipe(tmp_path, manifest_name("other"))
    claim = claim_folder(tmp_path, "case", ["case.obj"])
    claim.release()
    assert claim.removed == []


def test_a_named_pipe_in_place_of_an_output_is_refused_by_its_digest(tmp_path):
    from splinedeform.export import file_digest

    path = pipe(tmp_path, "case.obj")
    with pytest.raises(InputError, match="case.obj: the output file is a named pipe"):
        file_digest(path)


def test_a_named_pipe_beside_a_sculpt_save_is_not_the_same_file(tmp_path):
    from splinedeform.sculpt.save import same_file as _same_file

    source = tmp_path / "grid.npy"
    source.write_bytes(b"\x93NUMPY")
    assert not _same_file(pipe(tmp_path, "copy.npy"), source)
    assert _same_file(source, source)


def test_a_named_pipe_as_the_study_results_is_refused_by_bench_render(tmp_path):
    from splinedeform import bench

    pipe(tmp_path, "bench.json")
    with pytest.raises(InputError, match="bench.json: .*is a named pipe, not a regular file"):
        bench.render(tmp_path)


def test_a_named_pipe_given_to_the_key_reference_writer_is_refused(tmp_path, capsys):
    from splinedeform.scenario.reference import main

    path = pipe(tmp_path, "scenario.md")
    assert main([str(path)]) == 2            # named on stderr, exit code 2, no traceback
    assert "the Markdown file is a named pipe" in capsys.readouterr().err
