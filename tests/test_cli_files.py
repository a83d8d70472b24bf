"""Nothing lost: the command line and batches refuse, before any work, a plan that would write
over an input, write two outputs to one file or feed a folder's outputs back in; every error is
one line with its exit code; resume redoes an output whose bytes changed."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from texsynth import batch, cli, jobs
from texsynth.io import files, read_png, write_exr, write_png

from _images import ramp_photo

REPO = Path(__file__).resolve().parents[1]
FAST = ["--method", "heeger_bergen", "--scales", "2"]


def _run(capsys, *argv):
    code = cli.main(["-q", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def _tree(folder):
    return {p: p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture()
def lib(tmp_path):
    folder = tmp_path / "lib"
    folder.mkdir()
    write_png(folder / "good.png", ramp_photo((48, 48)))
    return folder


def _one_error_line(err, named):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and named in lines[0] and "Traceback" not in err, err


def test_a_batch_never_writes_over_a_photo_it_lists(lib, capsys):
    second = lib / "good_random_phase_32x32_s0.png"
    write_png(second, ramp_photo((48, 48), seed=3))
    (lib / "list.csv").write_text("photo\ngood.png\ngood_random_phase_32x32_s0.png\n")
    before = _tree(lib)
    code, _, err = _run(capsys, "batch", lib / "list.csv", "-o", lib, "--size", "32",
                        "--method", "random_phase")
    assert code == 2
    _one_error_line(err, "would overwrite the input")
    assert _tree(lib) == before


def test_a_batch_into_its_own_folder_is_refused(lib, capsys):
    before = _tree(lib)
    code, _, err = _run(capsys, "batch", lib, "-o", lib, "--size", "32", *FAST)
    assert code == 2
    _one_error_line(err, "next run")
    assert _tree(lib) == before


@pytest.mark.parametrize("outputs, named", [
    (["-o", "{out}/o.png", "--maps", "{m}/o.png"], "same file"),
    (["-o", "{out}/t.png", "--maps", "{m}/rough.png", "{n}/rough.png"], "same file"),
    (["-o", "{out}/o.png", "--preview", "--maps", "{m}/o_tiled.png"], "same file"),
])
def test_outputs_that_would_be_one_file_are_refused(tmp_path, capsys, outputs, named):
    for folder in ("m", "n"):
        (tmp_path / folder).mkdir()
        for name in ("o.png", "rough.png", "o_tiled.png"):
            write_png(tmp_path / folder / name, ramp_photo((48, 48)))
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    before = _tree(tmp_path)
    argv = [a.format(out=tmp_path / "out", m=tmp_path / "m", n=tmp_path / "n") for a in outputs]
    code, _, err = _run(capsys, "synthesize", tmp_path / "photo.png", "--size", "32", *argv)
    assert code == 2
    _one_error_line(err, named)
    assert _tree(tmp_path) == before and not (tmp_path / "out").exists()


def test_a_map_with_nan_is_refused_and_nothing_is_written(tmp_path, capsys):
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    bad = ramp_photo((48, 48)).copy()
    bad[5:10, 5:10] = np.nan
    write_exr(tmp_path / "rough.exr", bad)
    for command in ("synthesize", "tile"):
        code, _, err = _run(capsys, command, tmp_path / "photo.png", "-o", tmp_path / "o.png",
                            "--maps", tmp_path / "rough.exr",
                            *(["--size", "32", "--method", "multiscale_mrf"]
                              if command == "synthesize" else []))
        assert code == 3
        _one_error_line(err, "rough.exr: 75 of 6912 values are NaN or infinite")
        assert sorted(p.name for p in tmp_path.iterdir()) == ["photo.png", "rough.exr"]


def test_a_write_that_fails_midway_leaves_no_output_at_all(tmp_path, capsys, monkeypatch):
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    write_png(tmp_path / "normal.png", ramp_photo((48, 48), seed=2))
    (tmp_path / "out").mkdir()
    write_png(tmp_path / "out" / "o.png", ramp_photo((8, 8)))  # an old output: kept whole
    old = (tmp_path / "out" / "o.png").read_bytes()
    calls = []

    def full_disk(path, image, bits=8, atomic=True):
        calls.append(path)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        write_png(path, image, bits=bits)

    monkeypatch.setattr(files, "write_image", full_disk)  # io.write_images' writer
    code, _, err = _run(capsys, "tile", tmp_path / "photo.png", "-o", tmp_path / "out" / "o.png",
                        "--maps", tmp_path / "normal.png")
    assert code == 4 and len(calls) == 2
    _one_error_line(err, "No space left on device")
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["o.png"]
    assert (tmp_path / "out" / "o.png").read_bytes() == old


@pytest.mark.parametrize("make, code, named", [
    (lambda p: p.write_bytes(p.read_bytes()[:200]), 3, "photo.png"),  # truncated PNG
    (lambda p: p.write_bytes(b"\x76\x2f\x31\x01"), 3, "photo.png"),  # an EXR's magic alone
    (lambda p: (p.unlink(), p.mkdir()), 3, "is a folder"),
    (lambda p: (p.unlink(), os.mkfifo(p)), 3, "not a regular file"),  # opening it would hang
])
def test_unreadable_photos_are_one_line_with_exit_3(tmp_path, capsys, make, code, named):
    photo = tmp_path / "photo.png"
    write_png(photo, ramp_photo((64, 64)))
    make(photo)
    got, _, err = _run(capsys, "tile", photo, "-o", tmp_path / "o.png")
    assert got == code
    _one_error_line(err, named)
    assert not (tmp_path / "o.png").exists()


@pytest.mark.parametrize("argv, code, named", [
    (["--size", "0"], 2, "--size"),
    (["--size", "100000"], 2, "100000"),
    (["--seed", "-1"], 2, "seed"),
    (["--bogus"], 2, "--bogus"),
    (["--in-size", "100000"], 2, "--in-size"),  # the resampled photo over the largest side
    (["-o", "o.jpg", "--bits", "16"], 2, "--bits 16"),  # a JPEG holds 8 bits
])
def test_argument_errors_are_one_line_with_exit_2(tmp_path, capsys, argv, code, named):
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    got, _, err = _run(capsys, "synthesize", tmp_path / "photo.png", "-o", tmp_path / "o.png",
                       *FAST, *argv)
    assert got == code
    _one_error_line(err, named)


def test_an_unwritable_output_is_refused_before_the_work(tmp_path, capsys, monkeypatch):
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    monkeypatch.setattr(jobs, "execute", lambda *a, **k: pytest.fail("the work ran"))
    code, _, err = _run(capsys, "synthesize", tmp_path / "photo.png", "-o", "/proc/x/o.png",
                        *FAST)
    assert code == 4
    _one_error_line(err, "/proc/x")



@pytest.mark.parametrize("argv", [["-o", "o.png"], ["-o", "t.png", "--preview"]])
def test_an_output_that_is_a_folder_is_refused_before_the_work(tmp_path, capsys, monkeypatch,
                                                               argv):
    """os.replace onto a folder failed after the work, with a line naming no file."""
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    folder = tmp_path / ("o.png" if argv[1] == "o.png" else "t_tiled.png")
    folder.mkdir()
    monkeypatch.setattr(jobs, "execute", lambda *a, **k: pytest.fail("the work ran"))
    code, _, err = _run(capsys, "synthesize", tmp_path / "photo.png", "-o",
                        tmp_path / argv[1], *argv[2:], *FAST)
    assert code == 4
    _one_error_line(err, f"{folder}: a folder of that name is there")


def test_an_output_name_too_long_for_its_folder_is_refused_before_the_work(tmp_path, capsys,
                                                                         monkeypatch):
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    monkeypatch.setattr(jobs, "execute", lambda *a, **k: pytest.fail("the work ran"))
    code, _, err = _run(capsys, "synthesize", tmp_path / "photo.png", "-o",
                        tmp_path / ("x" * 300 + ".png"), *FAST)
    assert code == 4
    _one_error_line(err, "the name is 304 bytes long")


def test_over_the_time_budget_is_exit_5(tmp_path, capsys, monkeypatch):
    write_png(tmp_path / "photo.png", ramp_photo((48, 48)))
    monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", "0.000001")
    code, _, err = _run(capsys, "synthesize", tmp_path / "photo.png", "-o", tmp_path / "o.png",
                        *FAST)
    assert code == 5
    _one_error_line(err, "time budget")
    assert not (tmp_path / "o.png").exists()


def test_a_manifest_that_is_not_utf8_is_one_line_with_exit_3(lib, tmp_path, capsys):
    (lib / "list.csv").write_bytes("photo\ngood.png\nm\xe9tal.png\n".encode("latin-1"))
    code, _, err = _run(capsys, "batch", lib / "list.csv", "-o", tmp_path / "out")
    assert code == 3
    _one_error_line(err, "list.csv:3: not UTF-8")


@pytest.mark.parametrize("text, code, named", [
    (b"photo,window\ngood.png,5\n", 2, "list.csv:1: unknown column 'window'"),  # ignored before
    (b"photo\ngood.png\n\0\0\n", 3, "list.csv:3: a NUL byte"),  # was 'embedded null byte'
])
def test_a_manifest_with_a_misspelt_column_or_a_nul_byte_is_one_line(lib, tmp_path, capsys,
                                                                      text, code, named):
    (lib / "list.csv").write_bytes(text)
    got, _, err = _run(capsys, "batch", lib / "list.csv", "-o", tmp_path / "out")
    assert got == code
    _one_error_line(err, named)
    assert not (tmp_path / "out").exists()


def test_resume_redoes_an_output_whose_bytes_changed_or_whose_code_changed(lib, tmp_path,
                                                                          monkeypatch):
    defaults = batch.Defaults(method="heeger_bergen", size=(32, 32), params={"scales": 2})
    (job,) = batch.plan(lib, tmp_path / "out", defaults)
    assert jobs.run_job(job) == "done" and jobs.run_job(job) == "skipped"
    out = tmp_path / "out" / job.outputs[0]
    good = out.read_bytes()
    out.write_bytes(good[:100])  # truncated after the batch
    assert jobs.run_job(job) == "done" and out.read_bytes() == good
    write_png(out, read_png(out)[::-1])  # overwritten by another image
    assert jobs.run_job(job) == "done" and out.read_bytes() == good
    monkeypatch.setattr(jobs, "code_digest", lambda: "other code")
    assert not jobs.is_done(job, jobs.key(job))


def test_the_exit_codes_are_listed_in_help_and_in_the_batch_guide(capsys):
    with pytest.raises(SystemExit):
        cli.main(["tile", "--help"])
    text = capsys.readouterr().out
    guide = (REPO / "docs" / "BATCH.md").read_text()
    for code in jobs.EXIT_CODES:
        assert f"  {code} " in text and f"| {code} |" in guide, code
    assert "existing files" in text


def test_a_portrait_phone_jpeg_comes_out_upright_at_its_in_size_as_jpeg(tmp_path, capsys):
    image = pytest.importorskip("PIL.Image")
    stored = np.rint(ramp_photo((60, 80)) * 255).astype(np.uint8)  # stored landscape
    exif = image.Exif()
    exif[274] = 6  # shown turned a quarter: portrait, 60 wide and 80 high
    image.fromarray(stored).save(tmp_path / "IMG_1.jpg", exif=exif.tobytes(), quality=95)
    code, out, _ = _run(capsys, "tile", tmp_path / "IMG_1.jpg", "-o", tmp_path / "t.jpg",
                        "--in-size", "40")
    assert code == 0 and "t.jpg" in out
    with image.open(tmp_path / "t.jpg") as written:
        assert written.format == "JPEG" and written.size == (30, 40)  # upright, longer side 40


def _default_sigint():  # a non-interactive shell's background jobs ignore SIGINT; a terminal's
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("delay", [0.2, 2.5])  # while Python loads numpy and scipy, and after
def test_ctrl_c_at_any_moment_is_one_line_and_exit_130(tmp_path, delay):
    write_png(tmp_path / "photo.png", ramp_photo((64, 64)))
    command = [sys.executable, str(REPO / "texsynth_command.py"), "-q", "synthesize",
               str(tmp_path / "photo.png"), "-o", str(tmp_path / "o.png"), "--size", "2048"]
    run = subprocess.Popen(command, cwd=REPO, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True, preexec_fn=_default_sigint)
    time.sleep(delay)
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=60)
    assert run.returncode == 130
    _one_error_line(err, "interrupted")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["photo.png"]


@pytest.mark.parametrize("delay", [0.1, 0.3, 0.6])  # while Python imports the package
def test_ctrl_c_while_python_m_texsynth_starts_is_one_line_and_exit_130(tmp_path, delay):
    write_png(tmp_path / "photo.png", ramp_photo((64, 64)))
    command = [sys.executable, "-m", "texsynth", "-q", "synthesize", str(tmp_path / "photo.png"),
               "-o", str(tmp_path / "o.png"), "--size", "2048"]
    for _ in range(5):  # on a loaded machine, the first 0.1 s may still be Python's own start
        run = subprocess.Popen(command, cwd=REPO, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True, preexec_fn=_default_sigint)
        time.sleep(delay)
        run.send_signal(signal.SIGINT)
        _, err = run.communicate(timeout=60)
        if "texsynth" in err:  # else Python's start (site, runpy) had the Ctrl+C, not texsynth
            break
    assert run.returncode == 130
    _one_error_line(err, "interrupted")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["photo.png"]


# A start as numpy's and the libraries' imports meet a Ctrl+C, with texsynth/interrupts.py loaded by
# its path (no package import): the SIGINT comes at a known moment, not by chance as above.
_START = """
import importlib.util, signal, sys
spec = importlib.util.spec_from_file_location("interrupts", {path!r})
interrupts = importlib.util.module_from_spec(spec); spec.loader.exec_module(interrupts)
def numpy_like():  # numpy's own import code turns the Ctrl+C into an ImportError
    try:
        signal.raise_signal(signal.SIGINT)
    except KeyboardInterrupt:
        raise ImportError("Error importing numpy's C core") from None
def optional_like():  # a library's optional import takes it for a missing module
    try:
        signal.raise_signal(signal.SIGINT)
    except (KeyboardInterrupt, ImportError):
        pass
def broken():
    raise ImportError("a broken install")
with interrupts.while_starting(active={active}):
    {body}()
print("went on")
"""


@pytest.mark.parametrize("body, active, code, says", [
    ("numpy_like", True, 130, "interrupted"),
    ("optional_like", True, 130, "interrupted"),
    ("broken", True, 1, "a broken install"),  # a real failure is not called a Ctrl+C
    ("numpy_like", False, 1, "Error importing"),  # not the command: the import fails as it is
])
def test_a_ctrl_c_however_the_imports_pass_it_on_ends_the_start_with_one_line(body, active,
                                                                            code, says):
    script = _START.format(path=str(REPO / "texsynth" / "interrupts.py"), active=active, body=body)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         preexec_fn=_default_sigint, timeout=60)
    assert run.returncode == code and says in run.stderr and "went on" not in run.stdout
    if code == 130:
        _one_error_line(run.stderr, "interrupted")


def test_a_ctrl_c_ignored_stays_ignored_while_the_command_starts():
    script = _START.format(path=str(REPO / "texsynth" / "interrupts.py"), active=True,
                           body="optional_like")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
                         timeout=60)
    assert run.returncode == 0 and "went on" in run.stdout and run.stderr == ""
