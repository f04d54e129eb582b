"""The persistent compilation cache of the JAX networks (Elman, grey-Elman).

JAX compiles each network's forward pass and training step with XLA the first time a process needs them: about
4 s of the bundled record's ``analyze`` (the first axis's grey-Elman, 4.6 s against 0.15-0.25 s for the next two
axes).  JAX can keep the compiled programs on disk and load them in the next process (its persistent compilation
cache); this module points that cache at a folder of the user's cache directory, so that a second command skips
the compilation (measured: first-axis grey-Elman 4.6 -> 0.9 s, the whole ``analyze`` 27 -> 23 s at load 1.8).
The programs loaded are those XLA compiled, so the numbers are the same bits as a fresh compile's.

The folder: ``$FOGDRIFT_JAX_CACHE`` when set (an empty value or ``0``: no cache), else
``$XDG_CACHE_HOME/fogdrift/jax`` (``~/.cache/fogdrift/jax``).  A cache the user configured for JAX itself
(``JAX_COMPILATION_CACHE_DIR`` or ``jax.config``) is kept as it is; a folder that cannot be made leaves JAX
compiling every time, as without a cache.  ``filelock`` (a dependency) guards the entries between processes.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["ENV", "MAX_BYTES", "cache_dir", "enable"]

#: Environment variable naming the cache folder (empty or ``0``: no persistent cache).
ENV = "FOGDRIFT_JAX_CACHE"

#: Largest size of the cache folder [bytes]; JAX removes the least recently used programs beyond it.  Setting a size
#: also makes JAX read and write each entry under a file lock (``filelock``), so that processes compiling at the same
#: time (a fleet's workers) never read an entry another one is still writing.
MAX_BYTES = 256 * 2**20


def cache_dir(environ=None) -> Path | None:
    """The folder of fogdrift's JAX compilation cache, or None when ``FOGDRIFT_JAX_CACHE`` turns it off.

    Examples
    --------
    >>> str(cache_dir({"FOGDRIFT_JAX_CACHE": "/tmp/jc"})), cache_dir({"FOGDRIFT_JAX_CACHE": "0"})
    ('/tmp/jc', None)
    >>> str(cache_dir({"XDG_CACHE_HOME": "/var/cache/u"}))
    '/var/cache/u/fogdrift/jax'
    """
    env = os.environ if environ is None else environ
    chosen = env.get(ENV)
    if chosen is not None:
        return None if chosen.strip() in ("", "0") else Path(chosen).expanduser()
    base = env.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "fogdrift" / "jax"


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
