"""Ingest: event logs from CSV, XES and rosbag2 (TALE preparation) into the canonical
DataFrame of :mod:`robotale.eventlog.schema`, and writers for CSV, XES and OCEL 2.0."""
