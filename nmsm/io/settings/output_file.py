"""The file written by ``nmsm print-xml -o`` and ``nmsm upgrade-settings -o``: checked, then
written atomically.

Before anything is written (:func:`check_output`):

* the output's folder must exist (it is not created: a typo in it must not make folders);
* the output must not name a folder;
* an existing file is replaced only with ``--force``;
* *protected* files are never replaced, ``--force`` or not: the settings file being upgraded
  and every file it names (solver settings, model, data files). They are compared by
  identity (:func:`os.path.samefile`: the same inode), so another spelling, a symbolic
  link or a hard link of them is refused too; an existing file inside a *protected folder*
  (a data folder the settings read) is refused as well.

:func:`write_output` writes the text into a temporary file in the output's folder and moves
it into place with :func:`os.replace`, so a failure leaves the earlier file (or none), never
a half-written one.

The code is generic and lives in :mod:`nmsm.io.output_file` (every command's output paths);
it is re-exported here.
"""

from __future__ import annotations

from nmsm.io.output_file import OPTION, _same_file, check_output, write_output

__all__ = ["OPTION", "_same_file", "check_output", "write_output"]
