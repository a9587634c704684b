# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Logging every run as a rosbag2 MCAP bag, and reading it back; one module per contract.

- ``state_layout``: the ``linkage/state`` joint names and the coordinates they carry, both ways;
- ``definitions``: message definitions and type hashes from the ament index;
- ``metadata``: metadata.yaml (``BagMetadata``) and the QoS profiles in it;
- ``errors``: ``BagError``, an ``OSError``, and its kinds;
- ``writer``: ``BagWriter``, the MCAP file and metadata.yaml of one bag (plain Python);
- ``mcap_chunk``: message records written straight into mcap's open chunk, for the writer;
- ``repeated``: the latest message of each ``repeat_latest`` topic, for a split bag's next file;
- ``writer_process``: a ``BagWriter`` in a process of its own, fed through a pipe;
- ``recorder``: the node's side, ``Recorder`` (topics by rclpy class and QoS, encoded bytes);
- ``reader``: the messages and states of a bag, also of a killed run's;
- ``recovery``: a killed run's bag made complete;
- ``player``: republishing a bag (``linkage-replay``).

Only ``recorder`` and ``player`` use rclpy (and ``metadata.qos_profile``, which makes an rclpy
QoSProfile); the writer process never loads it. The CDR bytes of the messages logged, rosbag2's
split numbers and the writer process's CPUs come from ``shared``, beneath this package and
``run`` alike: the two never import each other.
"""
