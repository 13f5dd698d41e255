"""Hostile paths (issue 24 items 1, 2): nothing lost, nothing hangs.

Outputs that are the input, links, devices, FIFOs, full disks, bad folders, killed
writes; inputs that are FIFOs, devices, huge files. Run in-process through
``planners.cli.main`` (a subprocess only where a kill or a hang is the point).
"""
from __future__ import annotations

import hashlib
import os
import signal
import stat
import subprocess
import sys
import threading
import time

import pytest

from conftest import ROOT
from planners.cli import main
from planners.output import TMP_PREFIX, atomic_path, clean_stale, write_text

BASIC = os.path.join(ROOT, "scenarios", "basic.toml")


@pytest.fixture
def scene(tmp_path):
    p = tmp_path / "s.toml"
    p.write_bytes(open(BASIC, "rb").read())
    return p


def digest(p) -> str:
    return hashlib.sha256(open(p, "rb").read()).hexdigest()


def run(capsys, *argv):
    """(exit code, stdout, stderr lines) of ``cspace ARGV`` run in this process."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err.strip().splitlines()


def one_error(capsys, *argv, field=None):
    code, out, err = run(capsys, *argv)
    assert code == 2, (code, out, err)
    assert len(err) == 1 and err[0].startswith("error: "), err
    if field is not None:
        assert f": {field}: " in err[0], err
    return err[0], out


# ------------------------------------------------------------------ item 1: outputs


@pytest.mark.parametrize("cmd", ["plan", "show"])
@pytest.mark.parametrize("how", ["same", "symlink", "hardlink"])
def test_output_that_is_the_input_is_refused(capsys, scene, tmp_path, cmd, how):
    before = digest(scene)
    target = {"same": scene, "symlink": tmp_path / "l.toml", "hardlink": tmp_path / "h.toml"}[how]
    if how == "symlink":
        os.symlink(scene, target)
    elif how == "hardlink":
        os.link(scene, target)
    msg, out = one_error(capsys, cmd, scene, "--json", target, field="--json")
    assert "input" in msg and out == ""  # refused before any work
    assert digest(scene) == before and os.path.islink(target) == (how == "symlink")


def test_plot_through_a_link_to_the_input_is_refused(capsys, scene, tmp_path):
    before = digest(scene)
    link = tmp_path / "pic.png"
    os.symlink(scene, link)
    one_error(capsys, "plan", scene, "--plot", link, field="--plot")
    assert digest(scene) == before


@pytest.mark.parametrize("opt", ["--json", "--plot"])
@pytest.mark.parametrize("cmd", ["plan", "show"])
def test_empty_output_path_is_refused(capsys, scene, cmd, opt):
    msg, out = one_error(capsys, cmd, scene, opt, "", field=opt)
    assert out == ""


@pytest.mark.parametrize("argv", [["stability", "--json", ""], ["stability", "--plot", ""],
                                  ["generate", "maze", "--out", ""], ["bench", "x.toml", "--out", ""]])
def test_empty_paths_are_refused_by_every_command(capsys, argv):
    msg, out = one_error(capsys, *argv)
    assert "empty path" in msg and out == ""


def test_two_options_naming_one_file_are_refused(capsys, scene, tmp_path):
    one_error(capsys, "plan", scene, "--json", tmp_path / "a.png", "--plot", tmp_path / "a.png", field="--plot")


def test_a_symbolic_link_is_followed_and_survives(capsys, scene, tmp_path):
    target = tmp_path / "target.json"
    target.write_text("old\n")
    link = tmp_path / "out.json"
    os.symlink(target, link)
    code, _, err = run(capsys, "plan", scene, "--json", link)
    assert code == 0, err
    assert os.path.islink(link) and os.readlink(link) == str(target)
    assert target.read_text().startswith("{")


def test_a_dangling_link_creates_its_target(capsys, scene, tmp_path):
    link = tmp_path / "out.json"
    os.symlink(tmp_path / "new.json", link)
    assert run(capsys, "plan", scene, "--json", link)[0] == 0
    assert os.path.islink(link) and (tmp_path / "new.json").read_text().startswith("{")


def private_device(tmp_path, name: str, minor: int) -> str:
    """A private copy of /dev/null (minor 3), /dev/full (7) or /dev/zero (5) in tmp_path.

    Never the system's nodes: a broken build (as main was) replaces the device it is
    given by a regular file, and as root that would be the machine's /dev/null.
    """
    path = str(tmp_path / name)
    try:
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
        with open(path, "rb" if minor == 5 else "wb") as fh:  # a nodev mount refuses it here
            fh.read(1) if minor == 5 else None
    except (OSError, AttributeError):
        pytest.skip("cannot create a private device node here (not root, or a nodev mount)")
    return path


def test_a_character_device_is_written_not_replaced(capsys, scene, tmp_path):
    null = private_device(tmp_path, "null", 3)
    assert run(capsys, "plan", scene, "--json", null)[0] == 0
    assert stat.S_ISCHR(os.stat(null).st_mode)


def test_a_full_device_fails_with_one_line(capsys, scene, tmp_path):
    full = private_device(tmp_path, "full", 7)
    msg, _ = one_error(capsys, "plan", scene, "--json", full, field="--json")
    assert "No space" in msg and stat.S_ISCHR(os.stat(full).st_mode)


def test_a_fifo_with_a_reader_gets_the_output(capsys, scene, tmp_path):
    fifo = tmp_path / "out.fifo"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(open(fifo).read()))
    reader.start()
    time.sleep(0.2)  # the reader is blocked in open() until the writer comes
    code, _, err = run(capsys, "plan", scene, "--json", fifo)
    reader.join(10)
    assert code == 0, err
    assert got and got[0].startswith("{") and stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_a_fifo_without_reader_is_refused_not_waited_on(capsys, scene, tmp_path):
    fifo = tmp_path / "out.fifo"
    os.mkfifo(fifo)
    msg, _ = one_error(capsys, "show", scene, "--json", fifo, field="--json")
    assert "reader" in msg and stat.S_ISFIFO(os.stat(fifo).st_mode)


@pytest.mark.parametrize("where", ["under a file", "missing folder", "proc", "a folder"])
def test_bad_output_location_is_found_before_the_work(capsys, scene, tmp_path, where):
    path = {"under a file": scene / "r.json", "missing folder": tmp_path / "no" / "r.json",
            "proc": "/proc/cspace-test.json", "a folder": tmp_path}[where]
    msg, out = one_error(capsys, "plan", scene, "--json", path, field="--json")
    assert out == ""  # the plan's summary was never printed: refused before the work


def test_bench_out_under_a_file_is_found_before_the_work(capsys, scene):
    one_error(capsys, "bench", scene, "--out", scene / "x", "--runs", "1", "--times", "0.01", "-q", field="--out")


def test_a_replaced_file_keeps_its_permissions(tmp_path):
    p = tmp_path / "r.json"
    p.write_text("old\n")
    os.chmod(p, 0o640)
    write_text(str(p), "new\n")
    assert p.read_text() == "new\n" and stat.S_IMODE(os.stat(p).st_mode) == 0o640


def test_atomic_write_leaves_the_old_file_on_failure(tmp_path):
    p = tmp_path / "r.json"
    p.write_text("old\n")
    with pytest.raises(RuntimeError):
        with atomic_path(str(p)) as tmp:
            open(tmp, "w").write("half")
            raise RuntimeError("killed half-way")
    assert p.read_text() == "old\n" and os.listdir(tmp_path) == ["r.json"]


def test_kill_9_during_a_write_leaves_no_temporary(tmp_path):
    """A writer killed mid-save: the target is untouched, and no temporary remains
    (an O_TMPFILE has no name)."""
    target = tmp_path / "pic.png"
    target.write_bytes(b"old")
    code = ("import sys, time\nfrom planners.output import atomic_path\n"
            "with atomic_path(sys.argv[1]) as tmp:\n"
            "    open(tmp, 'wb').write(b'partial' * 1000)\n"
            "    print('writing', flush=True)\n"
            "    time.sleep(60)\n")
    p = subprocess.Popen([sys.executable, "-c", code, str(target)], cwd=ROOT, stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "writing"
    os.kill(p.pid, signal.SIGKILL)
    p.wait(10)
    clean_stale(str(tmp_path))
    assert target.read_bytes() == b"old" and os.listdir(tmp_path) == ["pic.png"]


def test_other_processes_temporaries_are_never_removed(tmp_path):
    # issue 36 item 7a: a dead pid's temporary is not ours to judge (pids are reused, and a
    # shared folder has other hosts' pids): only a process's own temporaries are removed.
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f"{TMP_PREFIX}{dead.pid}-0123abcd.png"
    live = tmp_path / f"{TMP_PREFIX}{os.getpid()}-0123abcd.png"  # this pid's name, not made by this code
    other = tmp_path / ".tmp-abcdefgh.png"  # not ours: never touched
    for f in (stale, live, other):
        f.write_bytes(b"x")
    write_text(str(tmp_path / "r.txt"), "new\n")
    assert clean_stale(str(tmp_path)) == 0
    assert sorted(os.listdir(tmp_path)) == sorted([stale.name, live.name, other.name, "r.txt"])


# ------------------------------------------------------------------ item 2: inputs that hang


def test_a_fifo_as_the_scenario_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)
    # a subprocess: on failure this would block in open() forever, so bound it
    r = subprocess.run([sys.executable, "-m", "planners.cli", "show", str(fifo)], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "regular file" in r.stderr


@pytest.mark.parametrize("name, minor", [("zero", 5), ("null", 3)])
def test_a_device_as_the_scenario_is_refused(tmp_path, name, minor):
    dev = private_device(tmp_path, name, minor)

    def small():  # a broken build reads /dev/zero forever: cap its memory, and time
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    r = subprocess.run([sys.executable, "-m", "planners.cli", "plan", dev], cwd=ROOT, capture_output=True,
                       text=True, timeout=60, preexec_fn=small)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr[-300:]
    assert "regular file" in r.stderr


def test_a_huge_scenario_is_refused_before_reading(capsys, tmp_path):
    big = tmp_path / "big.toml"
    with open(big, "wb") as fh:  # sparse: costs no disk
        fh.truncate(64 * 2**20 + 1)
    msg, _ = one_error(capsys, "show", big, field="file")
    assert "64 MiB" in msg


def test_a_folder_as_the_scenario_is_refused(capsys, tmp_path):
    one_error(capsys, "plan", tmp_path, field="file")


# ------------------------------------------------------------------ item 2: generate is bounded


def test_generate_gives_up_after_a_few_candidates_and_says_why(monkeypatch):
    from planners.cli import generate as gen

    calls = []

    def never(scene, bar=None):
        calls.append(1)
        return "start and goal not connected"

    monkeypatch.setattr(gen, "_solvable", never)
    with pytest.raises(gen.GenerateError, match="10 x start and goal not connected"):
        gen.generate("disks", seed=0, size=5)
    assert len(calls) == gen.ATTEMPTS <= 10


def test_generate_never_runs_the_unbounded_search(monkeypatch):
    import cspace.paths.shortest

    def forbidden(*a, **k):
        raise AssertionError("the shortest-path search has no time bound here")

    monkeypatch.setattr(cspace.paths.shortest, "shortest_path", forbidden)
    from planners.cli.generate import generate

    assert generate("disks", seed=1, size=40).startswith("# generated by")


@pytest.mark.parametrize("args, field", [
    (["disks", "--seed", "-1"], "--seed"),
    (["narrow", "--ratio", "1e300"], "--ratio"),
    (["narrow", "--ratio", "nan"], "--ratio"),
    (["disks", "--size", "10000000"], "--size"),
])
def test_generate_bad_options_exit_2(capsys, tmp_path, args, field):
    one_error(capsys, "generate", *args, "--out", tmp_path / "g.toml", field=field)
    assert not (tmp_path / "g.toml").exists()
