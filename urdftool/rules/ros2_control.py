"""Rule family ``ros2_control`` (issue 31): the ``<ros2_control>`` blocks of a robot, the
controllers YAML and the launch files that load them."""
