"""A plugin whose format sniffer never returns (geobrep's own reproducer, issue 15 item 7)."""

import time

from geobrep.plugins import FormatSpec, hookimpl


def sniff(head: bytes) -> bool:
    time.sleep(3600)
    return True


@hookimpl
def geobrep_register_formats(registry):
    registry.add(FormatSpec(name="sniff-hangs", reader=lambda p, o: None, sniff=sniff))
