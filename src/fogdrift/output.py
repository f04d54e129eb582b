"""Output folders that never hold a half-written file, nor a stale one from an earlier run.

* :func:`check_out_dir` validates a folder **before any work**: it must be a writable folder, or not exist yet
  with a writable parent folder (a missing parent is an error unless ``create_parents``; it is usually a typo).
* :func:`atomic_path` writes a file through a temporary name in the same folder (``.fogdrift-tmp-<pid>-<name>``,
  same suffix, so ``np.savez`` and ``savefig`` see the real extension) and renames it when complete: the final
  name holds a complete file or nothing.
* :class:`OutputDir` is one run's output folder.  Inside ``with OutputDir(...)``, every :func:`atomic_path`
  under it is recorded in a manifest (:data:`MANIFEST`, JSON, rewritten after each file).  At the run's first
  previous run's files are replaced only once this run is complete: a file of the previous run that this run
  writes again is first moved aside (into the folder :data:`BACKUP_PREFIX` + process id), and when the run ends
  without error the previous run's other files (and the folders it created, when empty) and the moved ones are removed:
  the folder then holds the files of one run only, listed in its manifest with ``"complete": true``.  A run
  that fails or is interrupted puts the previous run's files back and takes its own away (the folder is as it
  was before the run; a run killed outright is taken back by the next run there, :func:`recover`).  Leftover
  temporary files of a process that no longer runs are removed at the first write.

Inputs are sacred (checked when the run starts, before any work; :meth:`OutputDir.__enter__`): a run whose
previous-run files (which it replaces) include one of its inputs (``protect``: files or folders, e.g. a bundle
folder) is refused; so is an output that would replace an input, or a file fogdrift did not write (one not
listed in the folder's manifest, e.g. a user's own ``allan.json``) -- the expected names at the start, every
other name at its write.

An interrupted run into a new folder leaves only complete files; :meth:`OutputDir.summary` says which were
written and which were not.

One run per folder at a time: :class:`OutputDir` holds an exclusive ``flock`` on :data:`LOCK` in the folder from
its start (a folder that does not exist yet is created then, and removed again if the run wrote nothing) to its
end; a second run, also one started into the same new folder at the same moment, is refused with
one line naming the first (its command, process id and start).  The kernel drops the lock when a process ends,
so a crashed run never leaves the folder locked.  An output that would replace one of the run's inputs is
refused.
"""

from __future__ import annotations

import contextlib
import errno
import glob as _glob
import json
import os
import re
import shutil
import tempfile
import threading
import time
from pathlib import Path

from . import __version__
from ._util import strict_json
from .errors import ConfigError, FogdriftError, ResourceError
from .interrupt import check, critical
from .interrupt import requested as check_requested

try:  # POSIX; elsewhere runs are not serialised (said in the docstring of FolderLock)
    import fcntl
except ImportError:  # pragma: no cover - not on the supported platforms
    fcntl = None

__all__ = ["MANIFEST", "LOCK", "TMP_PREFIX", "BACKUP_PREFIX", "OutputDir", "atomic_path", "check_out_dir",
           "active", "remove_stale_temporaries", "recover", "FolderLock"]

#: Name of the manifest a run keeps in its output folder.
MANIFEST = ".fogdrift-manifest.json"
#: Lock file of the run writing a folder (removed when the run ends; its lock dies with the process).
LOCK = ".fogdrift-lock"
#: Prefix of the temporary files (followed by the process id, a dash and the final name).
TMP_PREFIX = ".fogdrift-tmp-"
_TMP = re.compile(re.escape(TMP_PREFIX) + r"(\d+)-")
#: Folder (followed by the process id) where a run keeps the previous run's files it rewrites until it is complete.
BACKUP_PREFIX = ".fogdrift-previous-"

_active: list["OutputDir"] = []


def check_out_dir(path, *, create_parents: bool = False) -> Path:
    """Validate an output folder before any work; return it as an absolute Path (nothing is created).

    Raises
    ------
    ConfigError
        ``path`` exists and is not a folder; a parent is a file; the parent folder does not exist (unless
        ``create_parents``); the folder (or the one it would be created in) is not writable.  The message
        names the setting ``{opt:out}``.

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> check_out_dir(os.path.join(d, "run1")).name
    'run1'
    >>> check_out_dir(os.path.join(d, "missing", "run1"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: out= .../missing/run1: its parent folder .../missing does not exist; ...
    """
    p = Path(path).expanduser().absolute()
    try:
        return _check_out_dir(p, create_parents)
    except OSError as exc:
        if exc.errno != errno.ENAMETOOLONG:
            raise
        longest = max(p.parts, key=lambda part: len(os.fsencode(part)))
        shown = longest if len(longest) <= 40 else longest[:40] + "..."
        raise ConfigError(f"{{opt:out}}: the name {shown!r} ({len(os.fsencode(longest))} bytes; the whole path "
                          f"{len(os.fsencode(str(p)))}) is too long for the file system; choose a shorter "
                          "folder name") from None


def _check_out_dir(p: Path, create_parents: bool) -> Path:
    """:func:`check_out_dir` of the absolute path ``p``."""
    _check_links(p)
    if p.exists() and not p.is_dir():
        raise ConfigError(f"{{opt:out}} {p} exists and is not a folder; choose a folder (new or one fogdrift wrote "
                          "before)")
    if p.is_dir():
        _probe(p, p)
        return p
    parent = p.parent
    existing = parent
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ConfigError(f"{{opt:out}} {p}: {existing} is a file, not a folder")
    if existing != parent and not create_parents:
        raise ConfigError(f"{{opt:out}} {p}: its parent folder {parent} does not exist; create it first or choose "
                          "another folder")
    _probe(existing, p)
    return p


def _check_links(p: Path) -> None:
    """ConfigError if ``p`` or one of its parents is a symbolic link that leads nowhere (dangling, or a loop).

    Checked before any work: such a folder can be neither used nor created (``mkdir`` would fail after the
    whole computation).  A link to an existing folder is fine.
    """
    for q in reversed((p, *p.parents)):  # from the root down: the first component that fails is the culprit
        try:
            os.stat(q)
            continue
        except FileNotFoundError:
            if not q.is_symlink():
                return  # a folder that does not exist yet: the parent rules of check_out_dir apply
            reason = f"a symbolic link to {os.readlink(q)}, which does not exist (a dangling link)"
        except OSError as exc:
            if exc.errno != errno.ELOOP:
                return  # below a file (ENOTDIR), no permission: check_out_dir's own rules say it
            reason = "a symbolic link loop (the link leads back to itself)"
        where = "is" if q == p else f"cannot be used: {q} is"
        raise ConfigError(f"{{opt:out}} {p} {where} {reason}; remove or fix the link, or choose another folder")


def _probe(folder: Path, target: Path) -> None:
    """Create and remove a temporary file in ``folder``: the real test of writability (ACLs, read-only mounts)."""
    try:
        fd, name = tempfile.mkstemp(prefix=f"{TMP_PREFIX}{os.getpid()}-probe", dir=folder)
    except OSError as exc:
        raise ConfigError(f"{{opt:out}} {target}: cannot write in {folder} ({exc.strerror or exc})") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(name)


def remove_stale_temporaries(folder, killed=()) -> list[Path]:
    """Remove the temporary files of dead processes directly in ``folder`` (not recursive); return them.

    A temporary file is named ``TMP_PREFIX<pid>-...`` (:func:`atomic_path`, the writability probe of
    :func:`check_out_dir`); one whose process no longer runs was left by a run that was killed.  ``killed``:
    process ids the caller has just killed (their files go even before the processes are reaped).  Files of a
    live process, and anything not named so, are left alone.
    """
    folder = Path(folder)
    killed = {int(p) for p in killed}
    removed = []
    for stale in (folder.glob(TMP_PREFIX + "*") if folder.is_dir() else ()):
        m = _TMP.match(stale.name)
        if m and stale.is_file() and (int(m.group(1)) in killed or not _pid_alive(int(m.group(1)))):
            with contextlib.suppress(OSError):
                stale.unlink()
                removed.append(stale)
    return removed


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def active(path=None) -> "OutputDir | None":
    """The innermost active :class:`OutputDir` (that contains ``path``, if given), else None."""
    for out in reversed(_active):
        if path is None:
            return out
        try:
            Path(path).absolute().relative_to(out.path)
            return out
        except ValueError:
            continue
    return None


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path``; rename it to ``path`` when the block ends without error.

    Parent folders are created.  Inside an active :class:`OutputDir` that contains ``path``, the file is
    recorded in its manifest (and an interruption requested before the write raises first).  On an error
    the temporary file is removed and ``path`` is left as it was.

    Examples
    --------
    >>> import tempfile, os
    >>> target = Path(tempfile.mkdtemp()) / "table.csv"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("tau_s,adev_dph\\n")
    ...     print(tmp.name.startswith(".fogdrift-tmp-"), tmp.suffix, target.exists())
    True .csv False
    >>> target.read_text()
    'tau_s,adev_dph\\n'
    """
    out = active(path)
    if out is not None:
        with out.file(path) as tmp:
            yield tmp
        return
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = final.with_name(f"{TMP_PREFIX}{os.getpid()}-{final.name}")
    try:
        yield tmp
        os.replace(tmp, final)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise _write_error(final.parent, final.name, exc, "no partial file left") from exc
        raise


#: Write failures that mean the machine ran out of room, not a wrong folder.
_NO_ROOM = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC), errno.EFBIG}


def _write_error(folder: Path, rel: str, exc: OSError, left: str) -> FogdriftError:
    """One-line error for a file that could not be written (disk full, quota, read-only, permissions)."""
    code = errno.errorcode.get(exc.errno, "") if exc.errno else ""
    why = f"{exc.strerror or exc}" + (f" ({code})" if code else "")
    if exc.errno in _NO_ROOM:
        return ResourceError(f"{{opt:out}} {folder}: cannot write {rel}: {why}; {left}; free space on that disk "
                             "or choose another folder")
    return ConfigError(f"{{opt:out}} {folder}: cannot write {rel}: {why}; {left}; choose another folder")


def _out_of_memory(exc: BaseException) -> bool:
    """A MemoryError, or an error caused by one: ENOMEM, a shared library that could not be mapped (a lazy import
    of numba's LLVM under a memory limit raises OSError 'failed to map segment from shared object')."""
    seen = 0
    while exc is not None and seen < 8:
        if isinstance(exc, MemoryError) or getattr(exc, "errno", None) == errno.ENOMEM:
            return True
        if isinstance(exc, OSError) and "failed to map segment" in str(exc):
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


class FolderLock:
    """Exclusive, non-blocking ``flock`` on ``folder/LOCK``; the holder's description is written into the file.

    The file is unlinked while still locked when released; a process that opened the old file before the unlink
    sees another inode at the path after locking and tries again, so two runs never both hold the folder.
    Without ``fcntl`` (not POSIX) nothing is locked.
    """

    def __init__(self, folder: Path, who: str):
        self.path = folder / LOCK
        self.who = who
        self.fd = None

    def acquire(self) -> None:
        if fcntl is None or self.fd is not None:
            return
        for _ in range(8):
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                try:  # the holder writes who it is right after locking: give it a moment (a few ms) to do so
                    holder = ""
                    for _ in range(50):
                        holder = os.pread(fd, 512, 0).decode("utf-8", "replace").strip()
                        if holder:
                            break
                        time.sleep(0.01)
                    holder = holder or "another fogdrift run"
                finally:
                    os.close(fd)
                raise ConfigError(f"{{opt:out}} {self.path.parent}: {holder} is writing there now; wait for it to "
                                  "finish or choose another folder") from None
            try:
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # released and unlinked between our open and our lock: take the new file
                os.close(fd)
                continue
            os.ftruncate(fd, 0)
            os.write(fd, self.who.encode("utf-8"))
            self.fd = fd
            return
        raise ConfigError(f"{{opt:out}} {self.path.parent}: could not take the folder's lock {LOCK}")

    def release(self) -> None:
        if self.fd is None:
            return
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        with contextlib.suppress(OSError):
            os.close(self.fd)
        self.fd = None


def _inside(folder: Path, rel) -> Path | None:
    """``rel`` as a path inside ``folder``, or None if it is absolute or leaves it (a tampered manifest)."""
    if not isinstance(rel, str) or not rel or Path(rel).is_absolute():
        return None
    target = (folder / rel).absolute()
    try:
        target.resolve().relative_to(folder.resolve())
    except (ValueError, OSError):
        return None
    return target


def _read_doc(folder: Path) -> dict:
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return {}
    return doc if isinstance(doc, dict) and doc.get("fogdrift_manifest") == 1 else {}


def _write_doc(folder: Path, doc: dict) -> None:
    target = folder / MANIFEST
    tmp = target.with_name(f"{TMP_PREFIX}{os.getpid()}-{MANIFEST}")
    try:
        tmp.write_text(strict_json(doc, indent=1), encoding="utf-8")
        os.replace(tmp, target)
    except BaseException:  # disk full: no 0-byte temporary manifest left behind
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _strings(items) -> list[str]:
    return [r for r in (items if isinstance(items, list) else []) if isinstance(r, str)]


def _remove_empty_dirs(folder: Path, rels) -> None:
    for rel in sorted(_strings(rels), key=lambda r: r.count("/"), reverse=True):
        target = _inside(folder, rel)
        if target is not None and target.is_dir() and not target.is_symlink() and not any(target.iterdir()):
            with contextlib.suppress(OSError):
                target.rmdir()


def _take_back(folder: Path, files, dirs, previous: dict, backup) -> None:
    """Undo an unfinished run in ``folder``: remove its ``files``, put the previous run's files moved aside
    into ``backup`` back, remove the folders it created (``dirs``, when empty), restore the previous manifest."""
    for rel in _strings(files):
        target = _inside(folder, rel)
        if target is not None and target.is_file() and not target.is_symlink():
            with contextlib.suppress(OSError):
                target.unlink()
    kept = set(_strings(previous.get("files")))
    b = folder / backup if isinstance(backup, str) and backup.startswith(BACKUP_PREFIX) and "/" not in backup \
        else None
    if b is not None and b.is_dir() and not b.is_symlink():
        for moved in sorted(b.rglob("*")):
            rel = moved.relative_to(b).as_posix()
            target = _inside(folder, rel)
            if rel in kept and target is not None and moved.is_file() and not moved.is_symlink():
                with contextlib.suppress(OSError):
                    target.parent.mkdir(parents=True, exist_ok=True)
                    os.replace(moved, target)
        shutil.rmtree(b, ignore_errors=True)
    _remove_empty_dirs(folder, dirs)
    with contextlib.suppress(OSError):
        if previous:
            _write_doc(folder, previous)
        else:
            (folder / MANIFEST).unlink()


def _drop_previous(folder: Path, previous: dict, keep, backup, is_input=lambda p: False) -> None:
    """A run is complete: remove the previous run's files it did not write again (``keep``: the ones it wrote),
    the previous files it moved aside into ``backup``, and the previous run's folders that are now empty."""
    keep = set(keep)
    for rel in _strings(previous.get("files")):
        target = _inside(folder, rel)
        if rel in keep or target is None or is_input(target) or not target.is_file() or target.is_symlink():
            continue
        with contextlib.suppress(OSError):
            target.unlink()
    if isinstance(backup, str) and backup.startswith(BACKUP_PREFIX) and "/" not in backup:
        shutil.rmtree(folder / backup, ignore_errors=True)
    _remove_empty_dirs(folder, previous.get("dirs"))


def recover(folder, killed=()) -> bool:
    """Finish what a run killed outright (SIGKILL, power loss) left in ``folder``; return True if there was any.

    Its manifest says: a run that had not finished gets taken back (its files removed, the previous run's files
    it had moved aside put back, the previous manifest restored); a run that had finished but not yet removed the
    previous run's files gets them removed.  Only when that run's process no longer runs (or is in ``killed``);
    call it holding the folder's lock (:class:`OutputDir` does, at its start)."""
    folder = Path(folder)
    doc = _read_doc(folder)
    previous = doc.get("previous")
    if not isinstance(previous, dict):
        return False
    pid = doc.get("pid")
    if not isinstance(pid, int) or (pid not in set(killed) and _pid_alive(pid)):
        return False
    if doc.get("complete") is True:
        _drop_previous(folder, previous, _strings(doc.get("files")), doc.get("backup"))
        _write_doc(folder, {k: v for k, v in doc.items() if k not in ("previous", "pid", "backup")})
    else:
        _take_back(folder, doc.get("files"), doc.get("dirs"), previous, doc.get("backup"))
    return True


def _expand(paths) -> list[Path]:
    """The inputs as absolute paths; a wildcard that names no file as it is (``batch 'logs/*.csv'``) becomes
    the files it matches."""
    out = []
    for p in paths:
        if p is None:
            continue
        q = Path(p).expanduser()
        if not q.exists() and any(c in str(p) for c in "*?["):
            out += [Path(m).absolute() for m in sorted(_glob.glob(str(q), recursive=True))]
        out.append(q.absolute())
    return out


class OutputDir:
    """One run's output folder (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The folder; validated at once by :func:`check_out_dir`, created (and locked) at :meth:`__enter__`.
    command : str
        What wrote it (stored in the manifest).
    create_parents : bool
        Create missing parent folders (the CLI allows it only for its default ``out/<command>``).
    protect : sequence of paths
        The run's inputs: files, folders (every file in them; a bundle) or wildcards.  Never removed nor
        replaced: a run whose previous-run files include one is refused at its start.

    Attributes
    ----------
    written : list of str
        Files written so far by this run, relative to the folder, in order.
    removed : list of str
        Files of the previous run this run replaces (removed or overwritten once it is complete).
    taken_back : list of str
        Files this run had written and took back because it did not finish (the previous run's are kept).
    """

    def __init__(self, path, *, command: str, create_parents: bool = False, protect=()):
        self.path = check_out_dir(path, create_parents=create_parents)
        self.command = command
        self.create_parents = create_parents
        self.protect = _expand(protect)
        self.written: list[str] = []
        self.removed: list[str] = []
        self.taken_back: list[str] = []
        self.expected: list[str] = []
        self.complete = False
        self._created_dirs: list[str] = []
        self._pending: set[Path] = set()
        self._opened = False
        self._lock = threading.RLock()
        self._aborted = False
        self._ended = False
        self._made: list[Path] = []
        self._previous: dict = {}
        self._prev_files: list[str] = []
        self._backup = f"{BACKUP_PREFIX}{os.getpid()}"
        self._started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
        self._folder_lock = FolderLock(self.path, f"'fogdrift {command}' (process {os.getpid()}, started "
                                                   f"{self._started})")

    # -- context ------------------------------------------------------------------------------------
    def __enter__(self):
        """Create the folder if needed and lock it; take back a killed run; refuse, before any work, a run that
        would remove or replace one of its inputs or a file fogdrift did not write."""
        try:
            self._make_folder()
            self._folder_lock.acquire()
            recover(self.path)
            self._previous = {k: v for k, v in _read_doc(self.path).items() if k not in ("previous", "pid", "backup")}
            self._prev_files = []
            for rel in _strings(self._previous.get("files")):
                target = _inside(self.path, rel)
                if target is not None and target.is_file() and not target.is_symlink():
                    self._prev_files.append(rel)
            for rel in self._prev_files:
                inp = self._input_of(self.path / rel)
                if inp is not None:
                    was = self._previous.get("command")
                    raise ConfigError(
                        f"{{opt:out}} {self.path} holds the files of an earlier "
                        f"{repr('fogdrift ' + was) if isinstance(was, str) else 'fogdrift'} run, which this run would "
                        f"replace, and {rel} among them is an input of this run ({inp}); choose another output "
                        "folder")
            for rel in self.expected:
                self._check_target(self.path / rel, rel)
        except BaseException:
            self._folder_lock.release()
            self._unmake_folder()
            raise
        _active.append(self)
        return self

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None and self._opened:
                with self._lock:
                    self.complete = True
                    try:
                        self._write_manifest()
                    except OSError as err:
                        self.complete = False
                        self._end()
                        raise _write_error(self.path, MANIFEST, err, self.summary()) from err
                    self._end()
            else:
                self._end()
        finally:
            self._discard_pending()
            _active.remove(self)
            self._folder_lock.release()
            if not self._opened:
                self._unmake_folder()
        if exc is not None and not check_requested():
            if _out_of_memory(exc):
                inputs = ", ".join(sorted(str(p) for p in self.protect)) or "its input"
                raise ResourceError(
                    f"out of memory in 'fogdrift {self.command}' on {inputs}; {self.summary()}; run it with more "
                    "memory (a process limit: ulimit -v), or on a shorter log") from exc
            if isinstance(exc, OSError) and not isinstance(exc, FogdriftError) and exc.errno in _NO_ROOM:
                raise _write_error(self.path, getattr(exc, "filename", None) or "a file", exc,
                                   self.summary()) from exc
        return False

    def _end(self) -> None:
        """Complete: remove the previous run's files this run did not write again.  Not complete: take this
        run's files back when a previous run's are there (the folder stays as it was)."""
        with self._lock:
            if self._ended or not self._opened:
                return
            self._ended = True
            if not self._prev_files:
                return
            if self.complete:
                _drop_previous(self.path, self._previous, self.written, self._backup,
                               lambda t: self._input_of(t) is not None)
                with contextlib.suppress(OSError):
                    self._write_manifest()
            else:
                _take_back(self.path, self.written, self._created_dirs, self._previous, self._backup)
                self.taken_back, self.written, self.removed = list(self.written), [], []

    def expect(self, *names) -> None:
        """Declare files the run means to write (relative names), for :meth:`summary`."""
        self.expected.extend(str(n) for n in names)

    # -- inputs -------------------------------------------------------------------------------------
    def _input_of(self, target: Path) -> Path | None:
        """The input ``target`` is (or lies in, for an input folder that is not above this folder), else None."""
        t = Path(target).absolute()
        for p in self.protect:
            if t == p:
                return p
            with contextlib.suppress(OSError):
                if t.exists() and p.exists() and t.samefile(p):
                    return p
                if p.is_dir():
                    rp, out = p.resolve(), self.path.resolve()
                    if rp != out and rp not in out.parents and rp in t.resolve().parents:
                        return p
        return None

    def _check_target(self, final: Path, rel: str) -> None:
        """Refuse an output that would replace an input, or a file fogdrift did not write."""
        if self._input_of(final) is not None:
            raise ConfigError(f"{{opt:out}} {self.path}: the output {rel} would replace the input file {final}; "
                              "choose another output folder")
        if rel not in self.written and rel not in self._prev_files and (final.is_symlink() or final.is_file()):
            raise ConfigError(f"{{opt:out}} {self.path}: the output {rel} would replace {final}, a file fogdrift "
                              f"did not write (not listed in the folder's {MANIFEST}); move it away or choose "
                              "another output folder")

    # -- writing ------------------------------------------------------------------------------------
    def _rel(self, path) -> str:
        return Path(path).absolute().relative_to(self.path).as_posix()

    @contextlib.contextmanager
    def file(self, path):
        """Like :func:`atomic_path`, for a path inside this folder (relative paths are taken inside it)."""
        check()
        final = Path(path) if Path(path).is_absolute() else self.path / path
        rel = self._rel(final)
        self._check_target(final, rel)
        with self._lock:
            if self._aborted:
                raise RuntimeError("output folder closed after an interruption")
            try:
                self._open()
                self._make_dirs(final.parent)
            except OSError as exc:
                raise _write_error(self.path, rel, exc, self.summary()) from exc
            tmp = final.with_name(f"{TMP_PREFIX}{os.getpid()}-{final.name}")
            self._pending.add(tmp)
        try:
            yield tmp
            with critical(), self._lock:
                if self._aborted:
                    raise RuntimeError("output folder closed after an interruption")
                if rel in self._prev_files and rel not in self.written and final.is_file():
                    aside = self.path / self._backup / rel  # the previous run's file, until this run is complete
                    aside.parent.mkdir(parents=True, exist_ok=True)
                    os.replace(final, aside)
                new = rel not in self.written
                if new:  # listed before it appears: a kill in between leaves a listed file absent, never a file unlisted
                    self.written.append(rel)
                    self._write_manifest()
                try:
                    os.replace(tmp, final)
                except BaseException:
                    if new:
                        self.written.remove(rel)
                        with contextlib.suppress(OSError):
                            self._write_manifest()
                    raise
                self._pending.discard(tmp)
        except BaseException as exc:
            with self._lock:
                self._pending.discard(tmp)
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            if isinstance(exc, OSError) and not check_requested():  # disk full, quota: one line, no traceback
                raise _write_error(self.path, rel, exc, self.summary()) from exc
            raise

    def _make_folder(self) -> None:
        """Create the folder (and its missing parents, with create_parents) at the start of the run."""
        missing, f = [], self.path
        while not f.exists():
            missing.append(f)
            f = f.parent
        if len(missing) > 1 and not self.create_parents:
            raise ConfigError(f"{{opt:out}} {self.path}: its parent folder {self.path.parent} does not exist; "
                              "create it first or choose another folder")
        for d in reversed(missing):
            try:
                d.mkdir()
            except FileExistsError:  # another run created it at the same moment: the lock decides
                continue
            except OSError as exc:
                raise ConfigError(f"{{opt:out}} {self.path}: cannot create {d} ({exc.strerror or exc})") from None
            self._made.append(d)
        if not self.path.is_dir():
            raise ConfigError(f"{{opt:out}} {self.path} exists and is not a folder")

    def _unmake_folder(self) -> None:
        """Remove the folders :meth:`_make_folder` created, when they are (still) empty."""
        for d in reversed(self._made):
            with contextlib.suppress(OSError):
                d.rmdir()
        self._made = []

    def _make_dirs(self, folder: Path) -> None:
        missing = []
        f = folder
        while not f.exists():
            missing.append(f)
            f = f.parent
        for d in reversed(missing):
            d.mkdir(exist_ok=True)
            try:
                rel = self._rel(d)
            except ValueError:  # a parent of the output folder itself (create_parents)
                continue
            if rel != "." and rel not in self._created_dirs:
                self._created_dirs.append(rel)

    def _open(self) -> None:
        """First write: remove dead processes' temporaries (the previous run's files stay until the end)."""
        if self._opened:
            return
        folders = [self.path] + [d for d in (_inside(self.path, r) for r in _strings(self._previous.get("dirs")))
                                 if d is not None]
        for folder in folders:  # not recursive: --out may be a big folder of other things
            remove_stale_temporaries(folder)
        self.removed = list(self._prev_files)
        self._opened = True
        self._write_manifest()

    def _inside(self, rel) -> Path | None:
        """``rel`` as a path inside the folder, or None if it is absolute or leaves it."""
        return _inside(self.path, rel)

    def _read_manifest(self) -> dict:
        return _read_doc(self.path)

    def _write_manifest(self) -> None:
        doc = {"fogdrift_manifest": 1, "command": self.command, "fogdrift_version": __version__,
               "started": self._started, "complete": self.complete, "files": self.written,
               "dirs": self._created_dirs}
        if self._prev_files and not self._ended:  # how to take this run back, or finish it, if it is killed
            doc.update(previous=self._previous, pid=os.getpid(), backup=self._backup)
        _write_doc(self.path, doc)

    def _discard_pending(self) -> None:
        with self._lock:
            for tmp in list(self._pending):
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            self._pending.clear()

    # -- interruption -------------------------------------------------------------------------------
    def abort(self, timeout: float = 0.3) -> None:
        """From another thread, right before the process ends (the CLI's watchdog): stop further renames, remove
        unfinished temporary files, take this run's files back when a previous run's are there, and remove the
        folder's lock file (the lock would die with the process; its file would not)."""
        got = self._lock.acquire(timeout=timeout)
        try:
            self._aborted = True
            for tmp in list(self._pending):
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            self._pending.clear()
            if got:
                with contextlib.suppress(OSError):
                    self._end()
            self._folder_lock.release()
            if not self._opened:
                self._unmake_folder()
        finally:
            if got:
                self._lock.release()

    def summary(self) -> str:
        """One line: what this run wrote and what it did not (complete files only; no partial file left)."""
        where = str(self.path)
        if self.taken_back:
            return (f"nothing was kept in {where}: the earlier run's files there are unchanged (the "
                    f"{len(self.taken_back)} file(s) this run had written were taken back, a folder holds one "
                    "complete run)")
        if not self.written:
            kept = " (the earlier run's files there are unchanged)" if not self._opened and \
                (self.path / MANIFEST).exists() else ""
            return f"nothing was written to {where}{kept}"
        missing = [n for n in self.expected if n not in self.written]
        text = f"wrote {len(self.written)} complete file(s) to {where}: {_listing(self.written)}"
        if missing:
            text += f"; not written: {_listing(missing)}"
        elif not self.complete:
            text += "; the rest of the run's files were not written"
        if self.removed:
            text += f"; the earlier run's {len(self.removed)} file(s) there were replaced"
        return text + "; no partial file left"


def _listing(names, limit: int = 6) -> str:
    names = list(names)
    if len(names) <= limit:
        return ", ".join(names)
    return ", ".join(names[:limit]) + f" and {len(names) - limit} more"
