"""Output folders of the command-line tools: never lose a user's file.

Every tool (track, compare, scenarios) writes its results through :func:`output_folder`:

* the files are written into a hidden staging folder next to ``--out`` and moved into place
  only when the run succeeded; the staging folder is removed on any error, Ctrl-C or
  SIGTERM (:mod:`ddwmmr.cli.common` turns SIGTERM into an exception so this happens);
* the moves into ``--out`` hold the stop signals (:func:`_signals_deferred`): a signal
  arriving then is acted on once they are done, with the new output complete in place
  (:func:`committed_output`);
* a run killed outright (SIGKILL) cannot clean up: its staging folder, the folder of an
  earlier output it was replacing and its temporary files carry its host, process id and
  start time in their names (:func:`owner_token`), and the next run writing in the same
  folder removes those whose process is gone (:func:`remove_stale`), saying so in one
  line, after putting back every earlier output the killed run had moved aside, whichever
  ``--out`` the next run writes (:func:`_restore_killed`);
* every file is synced to disk (``fsync``) before the commit moves it into ``--out``, and
  the folders after the move (:func:`sync_folder`; not on Windows): a power cut leaves the
  earlier output or the new one, never an empty file under an output name;
* two runs writing the same ``--out`` at once are locked out of each other
  (:func:`output_lock`, a lock file beside ``--out``): the second is refused in one line,
  so a folder never holds files of two runs; a killed run's lock is taken over;
* a folder written by a tool carries a manifest, :data:`MANIFEST`, naming the tool, the
  package version and every file written;
* an existing ``--out`` is replaced only if it is empty, or if its manifest names the same
  tool and it holds nothing but the files that manifest lists. Anything else is refused
  with one line (a :class:`ParameterError`);
* a default, time-stamped ``--out`` (``fresh``) never replaces anything: two runs started
  within the same second, or finishing together, each get their own folder (``-2``...);
* a tool that keeps a cache inside its output folder while it runs (so an interrupted run
  resumes, ``python -m ddwmmr.bounds``) writes those files in place and lists them with
  :func:`list_in_manifest`: the folder stays this tool's own between runs;
* ``force=True`` (``--force``) also writes into a folder another tool or the user made,
  and even then deletes only the files its manifest lists: a file no manifest lists always
  survives (a new file that would overwrite it is refused). An interrupt while the files
  are moved leaves the old output or the new one, each with its manifest, never a mix.

Files and folders get the user's umask like any normal file (``0644``/``0755`` for the
usual ``022``), not the ``0600``/``0700`` of temporary files.
"""

from __future__ import annotations

from ddwmmr.outputs.atomic import first_free, sync_folder, write_atomic, write_new
from ddwmmr.outputs.checks import (
    MANIFEST,
    Existing,
    check_name_lengths,
    check_output_file,
    check_output_folder,
    check_output_path,
    check_writable,
    foreign_contents,
    inspect,
    missing_folders,
    nearest_existing,
    unwritable_message,
)
from ddwmmr.outputs.commit import (
    committed_output,
    list_in_manifest,
    output_folder,
    recording_commits,
    remove_created,
)
from ddwmmr.outputs.files import csv_text, file_mode, folder_mode, line_ending, package_version
from ddwmmr.outputs.lock import output_lock
from ddwmmr.outputs.owners import KEPT_PREFIX, STAGING_PREFIX, owner_token
from ddwmmr.outputs.recovery import remove_stale

__all__ = [
    "KEPT_PREFIX",
    "MANIFEST",
    "STAGING_PREFIX",
    "Existing",
    "check_name_lengths",
    "check_output_file",
    "check_output_folder",
    "check_output_path",
    "check_writable",
    "committed_output",
    "csv_text",
    "file_mode",
    "first_free",
    "folder_mode",
    "foreign_contents",
    "inspect",
    "line_ending",
    "list_in_manifest",
    "missing_folders",
    "nearest_existing",
    "output_folder",
    "output_lock",
    "owner_token",
    "package_version",
    "recording_commits",
    "remove_created",
    "remove_stale",
    "sync_folder",
    "unwritable_message",
    "write_atomic",
    "write_new",
]
