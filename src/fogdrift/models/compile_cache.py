"""The persistent compilation cache of the JAX networks (Elman, grey-Elman).

JAX compiles each network's forward pass and training step with XLA the first time a process needs them: about
4 s of the bundled record's ``analyze`` (the first axis's grey-Elman, 4.6 s against 0.15-0.25 s for the next two
axes).  JAX can keep the compiled programs on disk and load them in the next process (its persistent compilation
cache); this module points that cache at a folder of the user's cache directory, so that a second command skips
the compilation (measured: first-axis grey-Elman 4.6 -> 0.9 s, the whole ``analyze`` 27 -> 23 s at load 1.8).
The programs loaded are those XLA compiled, so the numbers are the same bits as a fresh compile's.

The folder: ``$FOGDRIFT_JAX_CACHE`` when set (an empty value or ``0``: no cache), else
``$XDG_CACHE_HOME/fogdrift/jax`` (``~/.cache/fogdrift/jax``), and in it one sub-folder per processor model and
instruction-set features (:func:`host_tag`): JAX's own cache key names the platform ("cpu") but not the processor's
features, and a program compiled for one processor's vector instructions must not be loaded on another that lacks
them (a home folder shared by the machines of a cluster), as numba's cache keys its entries by them too.  A cache
the user configured for JAX itself (``JAX_COMPILATION_CACHE_DIR`` or ``jax.config``) is kept as it is; a folder
that cannot be made leaves JAX compiling every time, as without a cache.  ``filelock`` (a dependency) guards the
entries between processes.
"""

from __future__ import annotations

import hashlib
import os
import platform
from pathlib import Path

__all__ = ["ENV", "MAX_BYTES", "cache_dir", "enable", "host_tag"]

#: Environment variable naming the cache folder (empty or ``0``: no persistent cache).
ENV = "FOGDRIFT_JAX_CACHE"

#: Largest size of the cache folder [bytes]; JAX removes the least recently used programs beyond it.  Setting a size
#: also makes JAX read and write each entry under a file lock (``filelock``), so that processes compiling at the same
#: time (a fleet's workers) never read an entry another one is still writing.
MAX_BYTES = 256 * 2**20


def host_tag(cpuinfo: str | None = None) -> str:
    """Twelve hex digits naming this processor: its model and instruction-set feature flags (Linux
    ``/proc/cpuinfo``; elsewhere the machine and processor names Python reports).

    Examples
    --------
    >>> a = host_tag("model name : EPYC\\nflags : fpu sse2 avx2 avx512f\\n")
    >>> a == host_tag("model name : EPYC\\nflags : fpu sse2 avx2\\n"), len(a)
    (False, 12)
    """
    if cpuinfo is None:
        try:
            cpuinfo = Path("/proc/cpuinfo").read_text(errors="replace")
        except OSError:
            cpuinfo = ""
    keep = [line.split(":", 1)[1].strip() for line in cpuinfo.splitlines()
            if ":" in line and line.split(":", 1)[0].strip() in ("model name", "flags", "Features", "CPU part")]
    text = "\n".join(dict.fromkeys(keep)) or f"{platform.machine()} {platform.processor()}"
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def cache_dir(environ=None) -> Path | None:
    """The folder of fogdrift's JAX compilation cache on this processor, or None when ``FOGDRIFT_JAX_CACHE`` turns
    it off.

    Examples
    --------
    >>> cache_dir({"FOGDRIFT_JAX_CACHE": "/tmp/jc"}).parent.as_posix(), cache_dir({"FOGDRIFT_JAX_CACHE": "0"})
    ('/tmp/jc', None)
    >>> cache_dir({"XDG_CACHE_HOME": "/var/cache/u"}).parent.as_posix()
    '/var/cache/u/fogdrift/jax'
    """
    env = os.environ if environ is None else environ
    chosen = env.get(ENV)
    if chosen is not None:
        if chosen.strip() in ("", "0"):
            return None
        root = Path(chosen).expanduser()
    else:
        root = Path(env.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")) / "fogdrift" / "jax"
    return root / host_tag()


def enable(jax) -> Path | None:
    """Point ``jax``'s persistent compilation cache at :func:`cache_dir`; returns the folder, or None where the
    user's own JAX cache setting is kept, the cache is turned off, or the folder cannot be made.

    Every program is cached, whatever its compile time or size (the networks' are small: about 300 kB for the
    bundled record's ``analyze``), in at most :data:`MAX_BYTES`, each entry read and written under a file lock.
    """
    if os.environ.get("JAX_COMPILATION_CACHE_DIR") or jax.config.jax_compilation_cache_dir:
        return None
    folder = cache_dir()
    if folder is None:
        return None
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    jax.config.update("jax_compilation_cache_dir", str(folder))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    jax.config.update("jax_compilation_cache_max_size", MAX_BYTES)
    return folder
