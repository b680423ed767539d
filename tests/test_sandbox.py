"""The sandboxed reader of ``--untrusted`` attacked directly: ``sandbox.run_test_payload`` runs
Python inside the confined child (the CLI's child, plus a test switch no CLI option sets), so
the walls are tested independently of the xacro interpreter: whatever code reaches the child
cannot raise its limits, write, exec, fork, open a socket, signal or trace another process, or
read a secret or a file outside the package."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from conftest import ROOT, WallLessWaiting, run_urdftool

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux sandbox")

ATTACK = r'''
import ctypes, os, resource, signal, socket, subprocess, threading
PACKAGE, SECRET_FILE, MARKER = {package!r}, {secret_file!r}, {marker!r}
result = {{}}

def attempt(name, action):
    try:
        result[name] = ["done", repr(action())[:200]]
    except BaseException as exc:
        result[name] = ["refused", type(exc).__name__]

INF = resource.RLIM_INFINITY
for limit in ("RLIMIT_AS", "RLIMIT_CPU", "RLIMIT_FSIZE", "RLIMIT_NOFILE", "RLIMIT_NPROC"):
    which = getattr(resource, limit)
    attempt("raise " + limit, lambda: resource.setrlimit(which, (INF, INF)))
    attempt("prlimit " + limit, lambda: resource.prlimit(0, which, (INF, INF)))
attempt("write in the package", lambda: open(os.path.join(PACKAGE, "MARKER"), "w").write("x"))
attempt("write a marker", lambda: open(MARKER, "w").write("x"))
attempt("create with os.open", lambda: os.open(MARKER, os.O_CREAT | os.O_WRONLY))
attempt("execv", lambda: os.execv("/bin/sh", ["sh", "-c", "touch " + MARKER]))
attempt("subprocess", lambda: subprocess.run(["/bin/sh", "-c", "touch " + MARKER]))
attempt("posix_spawn", lambda: os.posix_spawn("/bin/sh", ["sh", "-c", "touch " + MARKER],
                                              {{}}))
result["system"] = os.system("touch " + MARKER)
attempt("fork", os.fork)
attempt("inet socket", lambda: socket.socket(socket.AF_INET, socket.SOCK_STREAM))
attempt("unix socket", lambda: socket.socket(socket.AF_UNIX, socket.SOCK_STREAM))
attempt("own environ", lambda: open("/proc/self/environ", "rb").read())
attempt("parent environ", lambda: open("/proc/%d/environ" % os.getppid(), "rb").read())
attempt("parent memory", lambda: open("/proc/%d/mem" % os.getppid(), "rb").read(1))
attempt("file outside the package", lambda: open(SECRET_FILE).read())
attempt("/etc/passwd", lambda: open("/etc/passwd").read())
attempt("signal the parent", lambda: os.kill(os.getppid(), 0))
attempt("signal everyone", lambda: os.kill(-1, 0))
attempt("signal the group", lambda: os.killpg(0, 0))
libc = ctypes.CDLL(None, use_errno=True)
traced = libc.ptrace(16, os.getppid(), 0, 0)  # PTRACE_ATTACH
result["ptrace"] = [traced, ctypes.get_errno()]
# what must still work: reading the package, threads (numeric libraries), its own signals
attempt("file in the package", lambda: open(os.path.join(PACKAGE, "robot.urdf")).read())
thread = threading.Thread(target=lambda: None)
attempt("thread", lambda: (thread.start(), thread.join()))
attempt("signal itself", lambda: os.kill(os.getpid(), 0))
attempt("allocate 2 GB", lambda: len(bytearray(2 << 30)))
'''

REFUSED = ["raise RLIMIT_AS", "raise RLIMIT_CPU", "raise RLIMIT_FSIZE", "raise RLIMIT_NOFILE",
           "raise RLIMIT_NPROC", "prlimit RLIMIT_AS", "prlimit RLIMIT_CPU", "prlimit RLIMIT_FSIZE",
           "prlimit RLIMIT_NOFILE", "prlimit RLIMIT_NPROC", "write in the package",
           "write a marker", "create with os.open", "execv", "subprocess", "posix_spawn", "fork",
           "inet socket", "unix socket", "parent environ", "parent memory",
           "file outside the package", "/etc/passwd", "signal the parent", "signal everyone",
           "allocate 2 GB"]


def test_every_layer_is_active_here():
    """This machine (and CI, on the same kind) has Landlock and seccomp: all layers hold."""
    from urdftool import sandbox

    layers = sandbox.layers()
    assert layers["landlock"].startswith("abi "), layers
    assert layers["seccomp"].startswith("allowlist: "), layers
    assert layers["landlock_net"] == "TCP bind and connect denied", layers
    assert layers["landlock_scopes"] == "signals and abstract unix sockets kept inside", layers
    assert layers["no_new_privs"] == "on" and layers["capabilities"] == "dropped"
    assert layers["rlimits"].startswith("hard:")


def test_code_in_the_child_cannot_get_out(tmp_path):
    """Run through an intermediary process whose real environment (the one /proc shows)
    holds a dummy secret, as a CI runner's does."""
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    (package / "robot.urdf").write_text('<robot name="r"><link name="a"/></robot>')
    secret_file = tmp_path / "secret.txt"
    secret_file.write_text("hunter2")
    marker = tmp_path / "PWNED"
    code = ATTACK.format(package=str(package), secret_file=str(secret_file), marker=str(marker))
    driver = ("import json, sys; from pathlib import Path; from urdftool import sandbox; "
              "own = open('/proc/self/environ', 'rb').read(); "
              "answer = sandbox.run_test_payload(sys.argv[1], [Path(sys.argv[2])]); "
              "answer['driver_environ_has_secret'] = b'hunter2' in own; "
              "print(json.dumps(answer))")
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "URDFTOOL_SECRET": "hunter2"}
    done = subprocess.run([sys.executable, "-c", driver, code, str(package)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=60, check=True)
    answer = json.loads(done.stdout)
    assert answer["driver_environ_has_secret"]  # the secret is there to be stolen
    outcome = answer["ok"]
    for name in REFUSED:
        assert outcome[name][0] == "refused", (name, outcome[name])
    own = outcome["own environ"]
    assert own[0] == "refused" or "hunter2" not in own[1]
    assert outcome["system"] != 0
    assert outcome["ptrace"][0] == -1
    assert "hunter2" not in json.dumps(outcome)
    assert not marker.exists() and not (package / "MARKER").exists()
    # the walls do not stop what reading a robot needs
    assert outcome["file in the package"][0] == "done"
    assert outcome["thread"][0] == "done" and outcome["signal itself"][0] == "done"


ALLOWLIST_ATTACK = r'''
import ctypes, errno, fcntl, os, socket, termios
libc = ctypes.CDLL(None, use_errno=True)
result = {}

def call(name, function, *args):
    ctypes.set_errno(0)
    value = function(*args)
    result[name] = [value, ctypes.get_errno()]

def attempt(name, action):
    try:
        result[name] = ["done", repr(action())[:200]]
    except OSError as exc:
        result[name] = ["refused", exc.errno]

F_SETSIG, F_SETOWN_EX, FIOASYNC, FIOSETOWN, SIOCSPGRP = 10, 15, 0x5452, 0x8901, 0x8902
IPC_PRIVATE, IPC_CREAT = 0, 0o1000
flags = fcntl.fcntl(0, fcntl.F_GETFL)
# signals to any process of the user: an owner and O_ASYNC on a descriptor
attempt("F_SETOWN", lambda: fcntl.fcntl(0, fcntl.F_SETOWN, os.getppid()))
attempt("F_SETSIG", lambda: fcntl.fcntl(0, F_SETSIG, 9))
attempt("F_SETOWN_EX", lambda: fcntl.fcntl(0, F_SETOWN_EX, bytes(8)))
attempt("O_ASYNC", lambda: fcntl.fcntl(0, fcntl.F_SETFL, flags | os.O_ASYNC))
attempt("FIOASYNC", lambda: fcntl.ioctl(0, FIOASYNC, b"\x01\x00\x00\x00"))
attempt("FIOSETOWN", lambda: fcntl.ioctl(0, FIOSETOWN, b"\x01\x00\x00\x00"))
attempt("SIOCSPGRP", lambda: fcntl.ioctl(0, SIOCSPGRP, b"\x01\x00\x00\x00"))
attempt("open O_ASYNC", lambda: os.open("/proc/self/status", os.O_RDONLY | os.O_ASYNC))
attempt("kill the parent", lambda: os.kill(os.getppid(), 15))
attempt("kill init", lambda: os.kill(1, 0))
# SysV IPC: objects that outlive the reader, other processes' shared memory
call("shmget", libc.shmget, IPC_PRIVATE, 4096, IPC_CREAT | 0o600)
call("shmat", libc.shmat, 0, None, 0)
call("msgget", libc.msgget, IPC_PRIVATE, IPC_CREAT | 0o600)
call("semget", libc.semget, IPC_PRIVATE, 1, IPC_CREAT | 0o600)
attempt("POSIX shm", lambda: os.open("/dev/shm/urdftool-q", os.O_CREAT | os.O_RDWR, 0o600))
attempt("socket", lambda: socket.socket(socket.AF_INET, socket.SOCK_DGRAM))
attempt("execve", lambda: os.execve("/bin/true", ["true"], {}))
call("ptrace", libc.ptrace, 16, os.getppid(), 0, 0)
# what a reader does with its own descriptors still works
attempt("F_GETFL", lambda: fcntl.fcntl(0, fcntl.F_GETFL))
attempt("F_SETFD", lambda: fcntl.fcntl(0, fcntl.F_SETFD, fcntl.FD_CLOEXEC))
attempt("O_NONBLOCK", lambda: (fcntl.fcntl(0, fcntl.F_SETFL, flags | os.O_NONBLOCK),
                               fcntl.fcntl(0, fcntl.F_SETFL, flags)))
attempt("isatty", lambda: os.isatty(0))
attempt("read a file", lambda: len(open(os.__file__, "rb").read()))
# its own interval timer: the trusted watchdog stops xacro's own loops here too (issue 21)
import signal, time
from urdftool import budget
attempt("setitimer", lambda: signal.setitimer(signal.ITIMER_REAL, 0))
spin = {}
exec(compile("def spin(end):\n    while time.monotonic() < end:\n        pass\n",
             "/site-packages/xacro/__init__.py", "exec"), {"time": time}, spin)

def watched():
    started = time.monotonic()
    try:
        with budget.watchdog(0.2, lambda: TimeoutError("late"), ("/xacro/",)):
            spin["spin"](started + 20)
    except TimeoutError:
        return time.monotonic() - started
    return None

attempt("watchdog", watched)
'''


def test_the_reader_may_only_read(tmp_path):
    """Allowlist, not denylist: with code running in the reader, no signal through O_ASYNC and
    a descriptor owner (F_SETOWN, F_SETSIG, FIOASYNC, FIOSETOWN), no SysV or POSIX IPC, no
    kill, socket, execve or ptrace; each refused by the filter itself (EPERM), while its own
    descriptors' flags and files still work."""
    from urdftool import sandbox

    answer = sandbox.run_test_payload(ALLOWLIST_ATTACK, [tmp_path])
    outcome = answer["ok"]
    assert outcome, answer
    for name in ("F_SETOWN", "F_SETSIG", "F_SETOWN_EX", "O_ASYNC", "FIOASYNC", "FIOSETOWN",
                 "SIOCSPGRP", "open O_ASYNC", "kill the parent", "kill init", "POSIX shm",
                 "socket", "execve"):
        assert outcome[name][0] == "refused", (name, outcome[name])
    for name in ("F_SETOWN", "F_SETSIG", "O_ASYNC", "FIOASYNC", "FIOSETOWN", "open O_ASYNC",
                 "socket", "execve"):
        assert outcome[name][1] == 1, (name, outcome[name])  # EPERM: the filter said no
    for name in ("shmget", "shmat", "msgget", "semget", "ptrace"):
        value, error = outcome[name]
        assert value == -1 and error == 1, (name, outcome[name])  # -1, EPERM
    for name in ("F_GETFL", "F_SETFD", "O_NONBLOCK", "isatty", "read a file", "setitimer"):
        assert outcome[name][0] == "done", (name, outcome[name])
    # the watchdog's timer signal interrupts a loop of xacro's at 0.2 s (not at 20 s)
    assert 0.2 <= float(outcome["watchdog"][1]) < 2.0, outcome["watchdog"]


def test_the_payload_door_is_shut_to_the_cli(tmp_path, monkeypatch):
    """The CLI's reader never runs a payload, even with the test switch in the environment
    and allowed with --allow-env."""
    from urdftool import sandbox

    monkeypatch.setenv(sandbox.TEST_SWITCH, "1")
    assert sandbox.TEST_SWITCH not in sandbox._child_env((sandbox.TEST_SWITCH,))
    child = sandbox.Child([tmp_path], 512, (sandbox.TEST_SWITCH,))
    try:
        answer = child.ask({"op": "exec", "code": "result = 1"}, 10, "test")
    except sandbox.SandboxFailure as exc:
        answer = str(exc)
    finally:
        child.close()
    assert "unknown request" in answer


def test_a_hung_reader_is_stopped_at_the_deadline(tmp_path):
    from urdftool import sandbox
    from urdftool.xacro_eval import LimitExceeded

    child = sandbox.Child([tmp_path], 512, test=True)
    with WallLessWaiting() as clock, pytest.raises(LimitExceeded, match="longer than"):
        child._exchange("import signal\nsignal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
                        "while True: pass", 0.5, "a payload")
    assert clock.seconds < 5 and child.process.poll() is not None


def test_a_subverted_child_can_send_only_data(tmp_path):
    """A pickle that would run a command in the parent, sent as the answer, is an unreadable
    answer."""
    import pickle

    from urdftool import sandbox

    marker = tmp_path / "PWNED-parent"

    class Exploit:
        def __reduce__(self):
            return os.system, (f"touch {marker}",)

    child = sandbox.Child([tmp_path], 512)
    child.buffer = pickle.dumps(Exploit()).replace(b"\n", b" ") + b"\n"
    with pytest.raises(sandbox.SandboxFailure, match="unreadable"):
        child._exchange({"op": "nothing"}, 10, "test")
    assert not marker.exists()


# -- bombs through every reading command --------------------------------------------------

DEEP = 20_000  # far past the parsers' 256 levels; the repair pass is linear in it


@pytest.fixture(scope="module")
def bombs(tmp_path_factory):
    import zipfile

    base = tmp_path_factory.mktemp("bombs")
    package = base / "pkg"
    (package / "urdf").mkdir(parents=True)
    (package / "meshes").mkdir()
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    with zipfile.ZipFile(package / "meshes" / "bomb.zae", "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("model.dae", b"<COLLADA>" + b" " * (300 << 20) + b"</COLLADA>")
    inertial = ('<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    mesh = '<geometry><mesh filename="package://pkg/meshes/bomb.zae"/></geometry>'
    arm = (f'<link name="base"/><link name="tip">{inertial}<visual>{mesh}</visual>'
           f'<collision>{mesh}</collision></link><joint name="j" type="revolute">'
           '<parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>'
           '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    files = {
        "zae": package / "urdf" / "zae.urdf",
        "zae-xacro": package / "urdf" / "zae.urdf.xacro",
        "huge": package / "urdf" / "huge.urdf",
        "zero": package / "urdf" / "zero.urdf",
        "fifo": package / "urdf" / "fifo.urdf",
        "deep": package / "urdf" / "deep.urdf",
        "deep-xacro": package / "urdf" / "deep.urdf.xacro",
    }
    files["zae"].write_text(f'<robot name="r">{arm}</robot>')
    files["zae-xacro"].write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                                  f'<xacro:property name="x" value="1"/>{arm}</robot>')
    with open(files["huge"], "wb") as handle:
        handle.truncate(200 << 20)  # sparse: 200 MB that cost no disk
    files["zero"].symlink_to("/dev/zero")
    os.mkfifo(files["fifo"])
    files["deep"].write_text('<robot name="r">' + "<a>" * DEEP + "</a>" * DEEP + "</robot>")
    files["deep-xacro"].write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        + "<a>" * DEEP + "</a>" * DEEP + "</robot>")
    sdf = {
        "zae": package / "zae.sdf",
        "huge": package / "huge.sdf",
        "zero": package / "zero.sdf",
        "deep": package / "deep.sdf",
    }
    sdf["zae"].write_text('<sdf version="1.7"><model name="m"><link name="a"><visual name="v">'
                          '<geometry><mesh><uri>meshes/bomb.zae</uri></mesh></geometry></visual>'
                          '</link></model></sdf>')
    with open(sdf["huge"], "wb") as handle:
        handle.truncate(200 << 20)
    sdf["zero"].symlink_to("/dev/zero")
    sdf["deep"].write_text('<sdf version="1.7"><model name="m">' + "<a>" * DEEP + "</a>" * DEEP
                           + "</model></sdf>")
    return files, sdf


ROBOT_COMMANDS = ["check", "expand", "inertia", "limits", "tree", "dh", "jacobian"]


def _bounded(*args, seconds=4.0):
    with WallLessWaiting() as clock:  # wall time less the machine's load
        result = run_urdftool(*args)
    elapsed = clock.seconds
    assert elapsed < seconds, (args, elapsed, clock.wall)
    assert "Traceback" not in result.err and "internal error" not in result.err, result.err
    if result.code == 2:
        assert len(result.err.strip().splitlines()) == 1, result.err
    return result


@pytest.mark.parametrize("command", ROBOT_COMMANDS)
def test_bombs_through_each_command_are_bounded(command, bombs, monkeypatch):
    files, _ = bombs
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(files["zae"].parent / f"cache-{command}"))
    for name, path in files.items():
        if command == "expand" and not name.endswith("xacro"):
            continue
        result = _bounded(command, "--untrusted", path)
        if name in ("huge", "zero", "fifo"):  # refused before reading, one located line
            assert result.code == 2 and str(path) in result.err
        if name.startswith("zae") and command in ("check", "inertia"):
            assert "unpacks to 300 MB" in result.out + result.err


def test_bombs_through_sim_and_convert_are_bounded(bombs, monkeypatch):
    files, sdf = bombs
    monkeypatch.setenv("URDFTOOL_CACHE_DIR", str(files["zae"].parent / "cache-sim"))
    for name in ("huge", "zero", "deep"):
        result = _bounded("convert", "--untrusted", sdf[name])
        assert result.code in (1, 2)
    for name in ("huge", "zero", "fifo", "deep-xacro"):
        result = _bounded("sim", "--untrusted", "--duration", "0.1", files[name], seconds=8)
        assert result.code in (1, 2)


def test_a_zae_bomb_costs_little_memory(bombs, tmp_path):
    """Through the real CLI: the whole run (parent and reader) stays far below 1 GB."""
    files, _ = bombs
    measure = ("import resource, subprocess, sys; "
               "subprocess.run([sys.executable, '-m', 'urdftool', 'inertia', '--untrusted', "
               "sys.argv[1]], capture_output=True); "
               "usage = resource.getrusage(resource.RUSAGE_CHILDREN); "
               "print(usage.ru_maxrss, usage.ru_utime + usage.ru_stime)")
    env = {**os.environ, "URDFTOOL_CACHE_DIR": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", measure, str(files["zae"])], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=60, check=True)
    peak, cpu = done.stdout.split()
    assert float(cpu) < 8  # CPU seconds of the run (the machine's other load does not count)
    assert int(peak) < 400 << 10  # KB: the largest process of the run



def test_doctor_lists_the_layers():
    result = run_urdftool("doctor", "--format", "json")
    report = json.loads(result.out)
    assert result.code == 0 and report["libraries"]["pyseccomp"] is True
    assert set(report["sandbox"]) == {"capabilities", "rlimits", "no_new_privs", "landlock",
                                      "landlock_net", "landlock_scopes", "seccomp"}
    text = run_urdftool("doctor").out
    assert "seccomp          allowlist: " in text and "landlock_scopes  signals" in text


def test_a_missing_layer_is_said_once(capsys):
    from urdftool import sandbox

    sandbox._NOTICED.discard("landlock")
    sandbox._notice({"landlock": "off: kernel without Landlock", "seccomp": "denylist"})
    sandbox._notice({"landlock": "off: kernel without Landlock"})
    err = capsys.readouterr().err
    assert err.count("without landlock (kernel without Landlock)") == 1 and "seccomp" not in err


@pytest.mark.parametrize("suffix", [".urdf.xacro", ".sdf"])
@pytest.mark.parametrize("failure", ["limit", "crash"])
def test_a_reader_that_fails_is_a_finding_of_a_real_rule(tmp_path, monkeypatch, suffix,
                                                         failure):
    """A reader stopped at the deadline or dead is reported under a registered rule (a finding
    under an unknown id would be dropped in silence)."""
    from urdftool import sandbox
    from urdftool.rules import load_all
    from urdftool.xacro_eval import LimitExceeded

    class Broken:
        def ask(self, *args):
            raise LimitExceeded("took too long") if failure == "limit" else \
                sandbox.SandboxFailure("the reader died")

    monkeypatch.setattr(sandbox, "_child", lambda roots: Broken())
    path = tmp_path / f"robot{suffix}"
    path.write_text('<sdf version="1.7"><model name="m"><link name="a"/></model></sdf>'
                    if suffix == ".sdf" else '<robot name="r" xmlns:xacro="http://www.ros.org/'
                    'wiki/xacro"><xacro:property name="x" value="1"/><link name="a"/></robot>')
    result = run_urdftool("check", "--untrusted", "--format", "json", path)
    (finding,) = [d for f in json.loads(result.out)["files"] for d in f["diagnostics"]
                  if "took too long" in d["message"] or "the reader died" in d["message"]]
    assert finding["rule"] in load_all() and finding["severity"] == "error"
    assert result.code == 1
