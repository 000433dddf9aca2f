"""A recording with the device its sidecar states, in the form the model fits: the one reader
that every command (identify, compare, predict, diagnose) and the Python API share.

:func:`read_device_recording` reads and checks the recording (``daq.read_checked_recording``),
resolves the device parameters from its sidecar and the caller's ``defaults`` (an explicit
choice of the user, such as the paper's Table 1: ``sidecar.resolve_known``) and, for a model,
rewrites a recording whose sidecar says ``friction_on: ground`` in absolute coordinates
(``kinds.on_ground``, the one place of that rewrite). Nothing is printed: the checks'
warnings and the notes on what was known, assumed and rewritten are returned, for the caller
to report.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from harvester.data.daq import CheckedRecording, read_checked_recording
from harvester.data.recording import Accepted
from harvester.data.sidecar import KnownParameters, read_sidecar, resolve_known


@dataclass
class DeviceRecording:
    """A checked recording (``checked``: table, kinds, step, sidecar, the checks' warnings),
    the device parameters it is fitted with (``known``), and what was done to it: the notes
    on the device parameters (those starting "ASSUMED" are warnings) and the lines of the
    rewrite to the ground's coordinates (empty where none was made)."""

    checked: CheckedRecording
    known: KnownParameters
    rewritten: list[str] = field(default_factory=list)

    @property
    def notes(self) -> list[str]:
        """What was known, assumed (a line starting "ASSUMED") and identified, in words."""
        return self.known.notes(self.checked.sidecar)

    @property
    def on_ground(self) -> bool:
        """Whether the recording was rewritten with its friction on the ground."""
        return bool(self.rewritten)


def read_device_recording(path: str | Path, defaults: Mapping[str, float] | None = None,
                          defaults_from: str = "", *, accept: Accepted | None = None,
                          known: Mapping[str, float] | None = None,
                          known_from: str | None = None,
                          for_model: bool = True) -> DeviceRecording:
    """The recording at ``path`` with its device (see the module's docstring).

    ``defaults``: device parameters assumed where the sidecar lacks them (``defaults_from``
    says where they come from); ``known``: the parameters to check the recording against
    instead of the sidecar's (a posterior's device, ``known_from`` names it); ``accept``: the
    kinds a command takes; ``for_model``: rewrite a ``friction_on: ground`` device in the
    ground's coordinates, without the screw-side mass m (the form every fit and prediction
    sees). DataError (file, line or column) for a bad recording or sidecar."""
    sidecar = read_sidecar(path)
    kp = resolve_known(sidecar, defaults, defaults_from)
    values = kp.values if known is None else known
    checked = read_checked_recording(path, values, known_from or kp.source, accept=accept)
    return model_form(checked, kp, str(path), values) if for_model else \
        DeviceRecording(checked, kp)


def model_form(checked: CheckedRecording, kp: KnownParameters, source: str,
               values: Mapping[str, float] | None = None) -> DeviceRecording:
    """The checked recording (read from ``source``) as a model sees it: as read, or, where
    its sidecar says ``friction_on: ground``, rewritten in the ground's coordinates with the
    device ``values`` (default ``kp``'s), without the screw-side mass m (``kinds.on_ground``,
    the one place of that rewrite; with a force input the recording is as read, the base
    being the ground)."""
    if checked.sidecar.friction_on != "ground":
        return DeviceRecording(checked, kp)
    from harvester.data.kinds import on_ground
    from harvester.data.recording import recording_kinds
    df, kept, done = on_ground(checked.data, kp.values if values is None else values, source)
    checked = replace(checked, data=df, kinds=recording_kinds(df, source))
    unused = {k for k in ("m",) if k not in kept}  # m, where the rewrite leaves it out
    kp = replace(kp, values={k: v for k, v in kp.values.items() if k not in unused},
                 given={k: v for k, v in kp.given.items() if k not in unused})
    return DeviceRecording(checked, kp, list(done))
