"""Sensors: camera and LIDAR (issue 17)."""
