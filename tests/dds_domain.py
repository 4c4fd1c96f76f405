"""Cyclone DDS for tests: on the loopback interface only, on a domain of this test run's own."""

from __future__ import annotations

import os

import pytest

LOOPBACK = """<CycloneDDS><Domain><General><Interfaces>
<NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast>
</General><Discovery><ParticipantIndex>auto</ParticipantIndex>
<MaxAutoParticipantIndex>100</MaxAutoParticipantIndex>
<Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>"""


def loopback(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> int:
    """Cyclone on 127.0.0.1 only, for this process and the ones it starts, on a domain no
    other test run shares (the pid decides); returns the domain."""
    config = tmp_path_factory.mktemp("dds") / "cyclonedds.xml"
    config.write_text(LOOPBACK)
    domain = 1 + os.getpid() % 200
    monkeypatch.setenv("CYCLONEDDS_URI", config.as_uri())
    monkeypatch.setenv("ROS_DOMAIN_ID", str(domain))
    return domain
