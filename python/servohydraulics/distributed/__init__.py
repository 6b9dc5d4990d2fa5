"""Distributed hybrid simulation: this project as a site that OpenSees' ``genericClient``
element and OpenFresco drive over TCP (``servohydraulics serve``), and a remote site as the
physical substructure of our own loops (:class:`RemoteSite`).  docs/distributed.md.
"""

from .protocol import QUANTITIES, Action, ProtocolError, Sizes, generic_client_sizes
from .remote import RemoteSite
from .server import Server, ServerStats
from .site import IdealSite, ModelSite, SiteError, make_site

__all__ = ["QUANTITIES", "Action", "ProtocolError", "Sizes", "generic_client_sizes", "RemoteSite", "Server",
           "ServerStats", "IdealSite", "ModelSite", "SiteError", "make_site"]
