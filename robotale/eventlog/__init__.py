"""Event logs: read from CSV and XES files or prepared from rosbag2 recordings (TALE) into
the canonical DataFrame of :mod:`robotale.eventlog.schema`, and written as CSV, XES and OCEL
2.0. Storing a log in the graph is :mod:`robotale.ekg`'s job (the ``ingest`` command)."""
