"""Format readers: one module per format, each defining ``open_table(path, **options) -> Table``.

See :mod:`fogdrift.io.readers.base` for the :class:`~fogdrift.io.readers.base.Table` contract
and :mod:`fogdrift.io.registry` for how a file's format is chosen.
"""

from .base import Table, split_unit_label

__all__ = ["Table", "split_unit_label"]
