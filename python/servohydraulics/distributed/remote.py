"""The other direction: a remote site (``servohydraulics serve``, OpenFresco's
SimAppSiteServer or a lab's own) as the physical substructure of our loops.

    site = RemoteSite("lab.example.org", 8090, dt=rths.DT, specimen=(m, c, k))
    trial = rths.run_trial(case, record, "sample", experimental=site)     # the RTHS loop

    ctrl = sh.RpsdController(rig)                                         # RPsD, stepped by hand
    site = RemoteSite("lab.example.org", 8090, dt=5e-4)
    for ag in ground_acceleration:
        site.step(ctrl.command(site.sensors(), ground_acceleration=ag))

Each sample the loop's command goes out as a trial displacement stamped with the sample's
end time ((k + 1) dt), and the site's acquired displacement, velocity and force come back
(one request without a reply, one with).  ``reset()`` (the loop calls it before a run)
reconnects when the connection has been used, so that the site starts again at rest.
"""

from __future__ import annotations

import math
import socket
from collections.abc import Sequence

import numpy as np

from .. import _core
from .protocol import Action, Sizes, request, unpack_daq

#: What RemoteSite asks for: control (displacement, time), acquisition (displacement, velocity,
#: acceleration, force, time).
SIZES = Sizes((1, 0, 0, 0, 1), (1, 1, 1, 1, 1), 256)
_ACQUIRED = ("displacement", "velocity", "acceleration", "force", "time")


class RemoteSite:
    """A one-actuator site across the network, with the protocol of the RTHS loop's
    experimental substructure (``rths.run_trial(..., experimental=RemoteSite(...))``).

    Args:
        host, port: the site server.
        dt: the loop's sample time [s].
        specimen: (m [kg], c [N s/m], k [N/m]) of the loop's feedback-force model; None: (0, 0,
            the site's initial stiffness).
        timeout: seconds to wait for the site before failing the run.
    """

    def __init__(self, host: str, port: int, dt: float, specimen: Sequence[float] | None = None,
                 timeout: float = 30.0):
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"invalid dt = {dt!r}: finite and > 0 [s]")
        self.host, self.port, self.dt, self.timeout = host, int(port), float(dt), float(timeout)
        self._sock: socket.socket | None = None
        self._used = True
        self.reset()
        self._specimen = (tuple(float(v) for v in specimen) if specimen is not None
                          else (0.0, 0.0, float(self.matrix(Action.GET_INITIAL_STIFFNESS)[0, 0])))

    # --- the experimental-substructure protocol (rths.PythonExperimentalSubstructure) ----------
    def reset(self) -> None:
        if self._used:
            self.close()
            self._connect()
        self.k = 0
        self.displacement = self.velocity = self.actuator_force = 0.0
        self._acquired = dict.fromkeys(_ACQUIRED, 0.0)

    def step(self, command: float) -> None:
        self._used = True
        t = (self.k + 1) * self.dt
        self._send(request(Action.SET_TRIAL_RESPONSE, SIZES, displacement=[command], time=[t]))
        self._send(request(Action.GET_DAQ_RESPONSE, SIZES))
        r = unpack_daq(self._recv(), SIZES)
        self._acquired = {q: float(r[q][0]) for q in _ACQUIRED}
        self.displacement, self.velocity, self.actuator_force = (self._acquired[q] for q in
                                                                 ("displacement", "velocity", "force"))
        self.k += 1

    def specimen(self) -> tuple[float, float, float]:
        return self._specimen

    # --- the controller/plant seam: the site's sensors for sh.RpsdController / sh.EftController ---
    def sensors(self) -> _core.Output:
        """The last acquired sample as the ``_core.Output`` a controller's ``command()`` reads
        (time, displacement, velocity, acceleration, force; the channels the site does not send,
        such as the pressure, are 0).  An RPsD test across the network, stepped by hand:

            sensors = site.sensors()
            for ag in ground_acceleration:
                site.step(ctrl.command(sensors, ground_acceleration=ag))
                sensors = site.sensors()
        """
        return _core.Output.from_channels(**self._acquired)

    # --- the rest --------------------------------------------------------------------------------
    def matrix(self, action: Action) -> np.ndarray:
        """A 1 x 1 matrix reply (GET_INITIAL_STIFFNESS ... GET_MASS)."""
        self._send(request(action, SIZES))
        return np.frombuffer(self._recv(), dtype=np.float64)[:1].reshape(1, 1).copy()

    def close(self) -> None:
        """Sends stop (99) and closes; the next reset() reconnects."""
        if self._sock is not None:
            try:
                self._send(request(Action.STOP, SIZES))
            except OSError:
                pass
            self._sock.close()
            self._sock = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _connect(self) -> None:
        s = socket.create_connection((self.host, self.port), timeout=self.timeout)
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        s.sendall(SIZES.to_bytes())
        self._sock, self._used = s, False

    def _lost(self, why: str) -> ConnectionError:
        return ConnectionError(f"the site {self.host}:{self.port} closed the connection ({why}; its log says why)")

    def _send(self, msg: bytes) -> None:
        if self._sock is None:
            raise ConnectionError(f"not connected to the site {self.host}:{self.port}")
        try:
            self._sock.sendall(msg)
        except OSError as e:
            raise self._lost(e.strerror or type(e).__name__) from None

    def _recv(self) -> bytes:
        n = SIZES.message_bytes
        buf = bytearray()
        while len(buf) < n:
            try:
                chunk = self._sock.recv(n - len(buf))
            except OSError as e:
                raise self._lost(e.strerror or type(e).__name__) from None
            if not chunk:
                raise self._lost("end of stream")
            buf += chunk
        return bytes(buf)
