"""The operator's console in the browser: ``rrc-pin console`` (the ``console`` extra: viser).

:class:`Console` serves one robot on a local port: the arm in 3-D with its hand axes and twist
arrows (:mod:`~rrc_pin.console.scene`, shapes from :mod:`~rrc_pin.console.visuals`), the
controls (:mod:`~rrc_pin.console.panel`) and the readouts (:mod:`~rrc_pin.console.readouts`),
shown by :mod:`~rrc_pin.console.view`. The :class:`ControlLoop` runs the controller in its own
thread at its own rate; the page only posts :mod:`~rrc_pin.console.commands` to its
:class:`Mailbox`. viser is imported when a console starts, so this package imports without it.
"""

from rrc_pin.console.access import Access
from rrc_pin.console.app import Console, console_robot
from rrc_pin.console.intake import Intake, TokenBucket
from rrc_pin.console.loop import ControlLoop, Notice, start_pose
from rrc_pin.console.mailbox import Mailbox
from rrc_pin.console.operator import Operator, OperatorSettings
from rrc_pin.console.rate import PeriodStats, Rate, TickClock
from rrc_pin.console.snapshot import Snapshot
from rrc_pin.console.visuals import Visuals, visuals_of

__all__ = [
    "Access",
    "Console",
    "ControlLoop",
    "Intake",
    "Mailbox",
    "Notice",
    "Operator",
    "OperatorSettings",
    "PeriodStats",
    "Rate",
    "Snapshot",
    "TickClock",
    "TokenBucket",
    "Visuals",
    "console_robot",
    "start_pose",
    "visuals_of",
]
