# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A node's bag: opened before anything is published, each message recorded, finalized once.

Both nodes log through it (``outputs.NodeOutputs`` for linkage_node, ``command_node``): the
bag's metadata (the node's parameters and the package's version), a log folder that cannot be
used refused as a ``log.folder`` ConfigurationError and any other failure to open it as a
StartupError, a write that fails stopping the log but never the messages (``error``, which the
node's status reports), and the bag finalized with its message count logged.
"""

from __future__ import annotations

import json
from typing import Any

from linkage_kinematics.bag.errors import LogFolderError
from linkage_kinematics.bag.metadata import BagMetadata, package_version
from linkage_kinematics.bag.recorder import Recorder, Topic
from linkage_kinematics.ros.process import StartupError
from linkage_kinematics.run.configuration import Logging
from linkage_kinematics.run.parameter_values import ConfigurationError
from rclpy.node import Node


class NodeLog:
    """
    The bag of ``topics`` as ``logging`` sets it, or none (``recorder`` None) with log.enabled off.

    Construction raises ConfigurationError naming log.folder if the folder cannot be written,
    StartupError for any other reason.
    """

    def __init__(self, node: Node, logging: Logging, topics: list[Topic],
                 parameter_values: dict[str, Any], cpus: set[int] | None) -> None:
        self._logger = node.get_logger()
        self.error: str | None = None
        self.recorder: Recorder | None = None
        if not logging.enabled:
            return
        metadata = {'parameters': json.dumps(parameter_values, sort_keys=True),
                    'package_version': package_version()}
        try:
            self.recorder = Recorder(logging.folder, topics=topics, metadata=metadata, cpus=cpus,
                                     max_bag_size=logging.max_bag_size,
                                     max_bag_duration=logging.max_bag_duration)
        except LogFolderError as error:
            raise ConfigurationError('log.folder', str(error)) from None
        except OSError as error:  # every BagError
            raise StartupError(f'cannot record: {error}') from None
        self._logger.info(f'recording to {self.recorder.bag_path}')

    def record(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """Hand one message's bytes to the bag, unless the log is off or has failed."""
        if self.recorder is None or self.error is not None:
            return
        try:
            self.recorder.record(topic, data, log_time_ns)
        except OSError as error:
            self._stop(error)

    def flush(self) -> None:
        """Have the bag writer write out what it holds (so that the log size is the bag's)."""
        if self.recorder is None or self.error is not None:
            return
        try:
            self.recorder.flush()
        except OSError as error:
            self._stop(error)

    def _stop(self, error: OSError) -> None:
        # the messages keep flowing; the node's status reports the lost log
        self.error = f'recording stopped: {error}'
        self._logger.error(self.error)

    def close(self) -> bool:
        """Finalize the bag (idempotent); False, with an error logged, if that failed."""
        if self.recorder is None:
            return True
        try:
            self.recorder.close()
        except OSError as error:
            self._logger.error(f'could not finalize the log: {error}')
            return False
        bag = self.recorder.bag_path
        self._logger.info(f'bag finalized: {bag}, {BagMetadata.read(bag).message_count} messages')
        return True
