"""Recognising an EPC package from its first bytes (no resqpy, no h5py)."""

from __future__ import annotations

__all__ = ["sniff_epc"]


def sniff_epc(head: bytes) -> bool:
    """A zip whose first member is the OPC content types, as EPC packages start."""
    return head.startswith(b"PK\x03\x04") and b"[Content_Types].xml" in head[:200]
