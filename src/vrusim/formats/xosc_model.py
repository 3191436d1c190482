"""What an imported OpenSCENARIO file says, as frozen dataclasses: entities, their initial state and motion.

World frame = vrusim's (x, y in m, heading in rad counter-clockwise from +x), as the export writes it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vrusim.sim.vru.shaped import PEAK_TO_MEAN_RATE

OVERRUN_M = 10.0
"""Straight continuation past the end of the ego route when the run stops there, m (written by
`vrusim.interop.osc_motion`, taken off again when a route is read back)."""


@dataclass(frozen=True)
class WorldPose:
    """A world position (m) with a heading (rad)."""

    x_m: float
    y_m: float
    heading_rad: float


@dataclass(frozen=True)
class EntityDef:
    """A `<ScenarioObject>`: kind ("vehicle", "pedestrian" or "misc"), its category and its geometry.

    The box is `length_m` x `width_m`, its centre `centre_x_m` ahead of the reference point. Axle and
    performance fields are None when not given (pedestrians, misc objects).
    """

    name: str
    kind: str
    category: str
    length_m: float
    width_m: float
    centre_x_m: float
    line: int
    wheelbase_m: float | None = None
    max_steer_rad: float | None = None
    max_accel_mps2: float | None = None
    max_decel_mps2: float | None = None
    properties: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Condition:
    """A start condition: "time" (simulation time >= value s), "travel" (the entity `ref` has travelled value m),
    "event_start" (event `ref` started, after `delay_s`) or "collision" (the entity `ref` touched `other`)."""

    kind: str
    value: float = 0.0
    ref: str = ""
    other: str = ""
    delay_s: float = 0.0
    line: int = 0


@dataclass(frozen=True)
class SpeedChange:
    """An event's AbsoluteTargetSpeed: reach `target_mps` at `rate_mps2` (None: at once) when `condition` holds."""

    event: str
    target_mps: float
    rate_mps2: float | None
    condition: Condition
    line: int


@dataclass(frozen=True)
class VertexTimes:
    """Simulation times (s) at which a trajectory reaches its vertices (`<TimeReference><Timing>` applied), and for
    each the (tag, line) of the element that gave it (a `<Vertex>`, a `<Clothoid>`, ...), for error messages."""

    times_s: tuple[float, ...]
    sources: tuple[tuple[str, int], ...]


@dataclass(frozen=True)
class Trajectory:
    """A followed polyline (vertices with headings), started at `offset_m` along it, from `condition`; `timing`:
    when it must reach each vertex (None: at the entity's own speed)."""

    vertices: tuple[WorldPose, ...]
    offset_m: float
    condition: Condition
    line: int
    timing: VertexTimes | None = None


@dataclass
class SampledShape:
    """A trajectory shape as vertices, each with its time as written (None: not given) and the (tag, line) of its
    element; `run_out`: the last vertex is a straight continuation added past the shape's end."""

    vertices: list[WorldPose] = field(default_factory=list)
    times_s: list[float | None] = field(default_factory=list)
    sources: list[tuple[str, int]] = field(default_factory=list)
    run_out: bool = False


@dataclass
class Motion:
    """Everything the file makes one entity do: initial pose and speed, trajectory, speed changes."""

    pose: WorldPose | None = None
    initial_speed_mps: float | None = None
    trajectory: Trajectory | None = None
    speed_changes: list[SpeedChange] = field(default_factory=list)
    sync: Synchronize | None = None


@dataclass
class StoryDef:
    """The storyboard: each entity's motion, the stop conditions and the time of day (None: not given)."""

    motions: dict[str, Motion]
    stop: list[Condition] = field(default_factory=list)
    night: bool | None = None
    placements: list[Placement] = field(default_factory=list)
    events: dict[str, Condition] = field(default_factory=dict)
    """Every event's start condition, by event name."""
    variable_changes: list = field(default_factory=list)
    """The events' VariableActions (`xosc_condition_kinds.VariableChange`), in file order."""


# ----------------------------------------------------------------------------------- actions and conditions (#19)

STEP_RATE_MPS2 = 1000.0
"""The rate a VRU's step speed change is given: the new speed within one simulation step (dt <= 0.1 s)."""


@dataclass(frozen=True)
class Ramp:
    """How a `<SpeedActionDynamics>` reaches its target: shape "step", or "linear", "cubic" or "sinusoidal" over
    `value` of `dimension` ("rate": m/s^2, "time": s, "distance": m; a linear ramp over a distance is at constant
    acceleration)."""

    shape: str
    dimension: str = "time"
    value: float = 0.0
    line: int = 0

    def rate_mps2(self, from_mps: float, to_mps: float) -> float | None:
        """The constant rate from `from_mps` to `to_mps` (m/s^2; of a cubic or sinusoidal shape its mean rate
        |to - from| / T); None for a step or a zero-length ramp."""
        if self.shape == "step" or (self.dimension != "rate" and self.value == 0.0):
            return None
        if self.dimension == "rate":  # of a cubic or sinusoidal shape: its peak rate (`xosc_speed_shapes`)
            return self.value / PEAK_TO_MEAN_RATE.get(self.shape, 1.0)
        if self.dimension == "time":
            return abs(to_mps - from_mps) / self.value
        return abs(to_mps * to_mps - from_mps * from_mps) / (2.0 * self.value)


@dataclass(frozen=True)
class RampedSpeedChange(SpeedChange):
    """A SpeedChange with its dynamics; `rate_mps2` holds the rate only when the dimension is "rate"."""

    ramp: Ramp = Ramp("step")


@dataclass(frozen=True)
class PlaceCondition(Condition):
    """ "distance" (entity `ref` within `value` m of the point) or "ttc" (time to collision with the point <= `value`
    s). The point is (x_m, y_m), or the reference point of entity `other`; `freespace`: measured from the bounding
    box (else from the reference point). `tag`: the element it was read from."""

    x_m: float = 0.0
    y_m: float = 0.0
    freespace: bool = False
    tag: str = ""


@dataclass(frozen=True)
class AnyCondition(Condition):
    """ "any": OR-ed `<ConditionGroup>`s of one condition each; holds as soon as one of `options` holds."""

    options: tuple[Condition, ...] = ()


# ----------------------------------------------------------------------- synchronisation and longitudinal distance


@dataclass(frozen=True)
class FinalSpeed:
    """A SynchronizeAction's `<FinalSpeed>`: "absolute" (`value` m/s) or relative to the master's speed at its
    target ("delta": + `value` m/s, "factor": x `value`); a steady state of `steady_m` m or `steady_s` s before
    the target (None: none)."""

    kind: str
    value: float
    steady_m: float | None = None
    steady_s: float | None = None
    line: int = 0


@dataclass(frozen=True)
class Synchronize:
    """A `<SynchronizeAction>` of event `event` started by `condition`: reach `target` (within `tolerance_m`) when
    entity `master` reaches `master_target` (within `master_tolerance_m`); `*_line`: the lines of the target
    elements."""

    event: str
    master: str
    master_target: WorldPose
    target: WorldPose
    master_tolerance_m: float
    tolerance_m: float
    final: FinalSpeed | None
    condition: Condition
    line: int
    master_line: int = 0
    target_line: int = 0


@dataclass(frozen=True)
class Placement:
    """A `<LongitudinalDistanceAction>` at t = 0: put entity `entity` `distance_m` (or `time_gap_s` x the master's
    speed) ahead of ("leading") or behind ("trailing") entity `master`, or on the side it stands ("any"), along
    the master's heading; `freespace`: between bounding boxes."""

    entity: str
    master: str
    distance_m: float | None
    time_gap_s: float | None
    freespace: bool
    displacement: str
    line: int
