# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The errors of the bag subpackage: one base, an ``OSError``.

Everything that can go wrong with a bag (a folder that cannot be created, a full disk, a file
that is not MCAP, a message definition that is not installed) is a ``BagError``, so a caller
that writes or reads bags catches ``OSError`` (or ``BagError``) once and shows its text, which
names the file or the type and the cause on one line.
"""

from __future__ import annotations


class BagError(OSError):
    """A bag cannot be created, written, read or recovered; the message says which and why."""


class BagExistsError(BagError, FileExistsError):
    """The bag folder to create already exists (nothing in it is touched)."""


class LogFolderError(BagError):
    """The folder the bags go into cannot be created or written."""


class MessageDefinitionError(BagError):
    """A message type's .msg file (or one it uses) cannot be found in the ament index."""
