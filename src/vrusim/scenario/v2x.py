"""V2X channel specification: message generation, latency, loss, outages, RSU perception error, track age.

A scenario's `v2x.channel` is a profile name (a key of `V2X_PROFILES`) or an inline `ChannelSpec`. User
profiles come from a YAML file (`load_profiles`). The models and their sources are in docs/models.md (V2X).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal, Self

from pydantic import (
    Field,
    SerializeAsAny,
    ValidationError,
    ValidatorFunctionWrapHandler,
    field_validator,
    model_validator,
)

from vrusim.errors import UserInputError
from vrusim.scenario.strict import StrictModel, error_message
from vrusim.scenario.yaml_file import read_yaml_file


class Generation(StrictModel):
    """When the RSU generates a message about a VRU it covers.

    every_step: every simulation step. periodic: every 1 / `rate_hz`. etsi_vam: the VRU awareness message
    rule of ETSI TS 103 300-3 (thresholds below, defaults from the standard).
    """

    mode: Literal["every_step", "periodic", "etsi_vam"] = "periodic"
    rate_hz: float = Field(10.0, gt=0, le=1000, description="periodic: messages per second")
    vam_position_change_m: float = Field(4.0, gt=0, description="etsi_vam: minReferencePointPositionChangeThreshold")
    vam_speed_change_mps: float = Field(0.5, gt=0, description="etsi_vam: minGroundSpeedChangeThreshold")
    vam_heading_change_deg: float = Field(
        4.0, gt=0, le=180, description="etsi_vam: minGroundVelocityOrientationChangeThreshold"
    )
    vam_min_interval_s: float = Field(0.1, ge=0, description="etsi_vam: T_GenVamMin")
    vam_max_interval_s: float = Field(5.0, gt=0, le=3600, description="etsi_vam: T_GenVamMax")

    @model_validator(mode="after")
    def _intervals(self) -> Self:
        if self.vam_min_interval_s > self.vam_max_interval_s:
            raise ValueError("vam_min_interval_s must not exceed vam_max_interval_s")
        return self


class LossSpec(StrictModel):
    """Base of every loss model's parameters (`v2x.channel.loss`): `model` names the model in the registry.

    A loss model's schema subclasses this with `model: Literal["<name>"] = "<name>"` and is registered with
    `register_loss_schema` (the simulation side registers it together with its packing and step:
    `vrusim.sim.v2x.loss.registry.register_loss_model`).
    """

    model: str


class NoLoss(LossSpec):
    """Every message sent within range arrives."""

    model: Literal["none"] = "none"


class BernoulliLoss(LossSpec):
    """Each message is lost independently with `probability`."""

    model: Literal["bernoulli"] = "bernoulli"
    probability: float = Field(ge=0, le=1)


class GilbertElliottLoss(LossSpec):
    """Two-state Markov loss (Gilbert 1960, Elliott 1963) on the RSU→ego link, one transition per message.

    Before each message the link moves good→bad with `p_good_to_bad` and bad→good with `p_bad_to_good`;
    the message is then lost with `loss_good` or `loss_bad`. Gilbert's model is loss_good 0, loss_bad 1.
    """

    model: Literal["gilbert_elliott"] = "gilbert_elliott"
    p_good_to_bad: float = Field(ge=0, le=1)
    p_bad_to_good: float = Field(gt=0, le=1)
    loss_good: float = Field(0.0, ge=0, le=1)
    loss_bad: float = Field(1.0, ge=0, le=1)

    @property
    def stationary_bad(self) -> float:
        """Long-run fraction of messages sent in the bad state: p_gb / (p_gb + p_bg)."""
        return self.p_good_to_bad / (self.p_good_to_bad + self.p_bad_to_good)

    @property
    def stationary_loss(self) -> float:
        """Long-run loss rate: (1 - pi_B) loss_good + pi_B loss_bad."""
        bad = self.stationary_bad
        return (1.0 - bad) * self.loss_good + bad * self.loss_bad

    @property
    def mean_bad_run_messages(self) -> float:
        """Mean number of consecutive messages in the bad state, 1 / p_bad_to_good (mean loss burst of Gilbert's
        model)."""
        return 1.0 / self.p_bad_to_good


class DistanceLoss(LossSpec):
    """Packet delivery ratio falling with the RSU–ego distance d: PDR(d) = 1 / (1 + exp((d - d50_m) / scale_m))."""

    model: Literal["distance"] = "distance"
    d50_m: float = Field(gt=0, description="distance where half of the messages arrive, m")
    scale_m: float = Field(gt=0, description="width of the fall-off, m (PDR 73 % at d50 - scale, 27 % at d50 + scale)")

    def delivery_ratio(self, distance_m: float) -> float:
        """PDR at `distance_m`."""
        z = (distance_m - self.d50_m) / self.scale_m
        return 1.0 / (1.0 + math.exp(z)) if z < 700 else 0.0


LossModel = NoLoss | BernoulliLoss | GilbertElliottLoss | DistanceLoss
"""The built-in loss models (more can be registered: `register_loss_schema`)."""
_LOSS_MODELS: dict[str, type[LossSpec]] = {}


def loss_model_name(schema: type[LossSpec]) -> str:
    """The `model` name a loss schema declares (the default of its `model` field)."""
    name = schema.model_fields["model"].default
    if not isinstance(name, str) or not name:
        raise TypeError(f"{schema.__name__}: a loss model declares its name as the default of `model`")
    return name


def register_loss_schema(schema: type[LossSpec]) -> str:
    """Make `loss.model: <name>` validate with `schema`; return the name. A name is registered once."""
    if not (isinstance(schema, type) and issubclass(schema, LossSpec)):
        raise TypeError(f"{schema!r}: a loss model schema subclasses vrusim.scenario.v2x.LossSpec")
    name = loss_model_name(schema)
    if _LOSS_MODELS.get(name, schema) is not schema:
        raise ValueError(f"loss model {name!r} is already registered (by {_LOSS_MODELS[name].__name__})")
    _LOSS_MODELS[name] = schema
    return name


def unregister_loss_schema(name: str) -> None:
    """Forget loss model `name` (plug-ins and tests; the built-ins cannot be removed)."""
    if name in _BUILTIN_LOSS_MODELS:
        raise ValueError(f"loss model {name!r} is built in")
    _LOSS_MODELS.pop(name, None)


def loss_schemas() -> Mapping[str, type[LossSpec]]:
    """The registered loss models' schemas by name (a read-only view)."""
    return MappingProxyType(_LOSS_MODELS)


_BUILTIN_LOSS_MODELS = tuple(
    register_loss_schema(schema) for schema in (NoLoss, BernoulliLoss, GilbertElliottLoss, DistanceLoss)
)


class Outage(StrictModel):
    """A scheduled discontinuity: nothing sent in [start_s, end_s) gets through, nothing arrives in it."""

    start_s: float = Field(ge=0)
    end_s: float = Field(gt=0)

    @model_validator(mode="after")
    def _ordered(self) -> Self:
        if self.end_s <= self.start_s:
            raise ValueError("end_s must be greater than start_s")
        return self


class ChannelSpec(StrictModel):
    """A V2X channel: generation, end-to-end delay, loss, outages, RSU perception error, ego track age.

    Delay of each message: `latency_s` + U(0, `jitter_s`) (uniform). The ego keeps a track per VRU from the
    newest message it has received, predicted to now at constant velocity, until it is `track_max_age_s` old.
    """

    generation: Generation = Generation()
    latency_s: float = Field(0.0, ge=0, le=10, description="fixed end-to-end delay, s")
    jitter_s: float = Field(0.0, ge=0, le=10, description="extra delay, uniform in [0, jitter_s], s")
    loss: SerializeAsAny[LossSpec] = NoLoss()
    outages: tuple[Outage, ...] = Field((), max_length=16, strict=False)  # a YAML list
    rsu_position_sigma_m: float = Field(0.0, ge=0, description="std. dev. of each reported position coordinate, m")
    rsu_speed_sigma_mps: float = Field(0.0, ge=0, description="std. dev. of each reported velocity component, m/s")
    track_max_age_s: float = Field(1.0, ge=0, le=3600, description="ego drops a track older than this, s")

    @field_validator("loss", mode="wrap")
    @classmethod
    def _typed_loss(cls, value: Any, handler: ValidatorFunctionWrapHandler) -> Any:
        """Validate `loss` as the model its `model` key names, so that errors read `loss.probability`."""
        if isinstance(value, LossSpec) and _LOSS_MODELS.get(value.model) is not type(value):
            raise ValueError(f"loss model {value.model!r} ({type(value).__name__}) is not registered")
        if not isinstance(value, dict):
            return handler(value)
        name = value.get("model", "none")
        if not isinstance(name, str) or name not in _LOSS_MODELS:
            raise ValueError(f"unknown loss model {name!r}; expected one of: {', '.join(_LOSS_MODELS)}")
        return _LOSS_MODELS[name].model_validate(value)  # its errors are reported under `loss`

    @model_validator(mode="after")
    def _tracks_outlive_the_delay(self) -> Self:
        """A track older than the longest delay would be dropped on arrival: V2X would silently vanish."""
        if self.track_max_age_s < self.latency_s + self.jitter_s:
            raise ValueError(
                f"track_max_age_s ({self.track_max_age_s:g} s) must be at least latency_s + jitter_s "
                f"({self.latency_s + self.jitter_s:g} s), or every message is dropped as it arrives"
            )
        return self

    @property
    def is_ideal(self) -> bool:
        """Whether this is the paper's channel: every step, no delay, loss, outage, noise, or track memory."""
        return (
            self.generation.mode == "every_step"
            and self.latency_s == 0.0
            and self.jitter_s == 0.0
            and isinstance(self.loss, NoLoss)
            and not self.outages
            and self.rsu_position_sigma_m == 0.0
            and self.rsu_speed_sigma_mps == 0.0
            and self.track_max_age_s == 0.0
        )


_BASE = {"generation": {"mode": "periodic", "rate_hz": 10.0}, "latency_s": 0.1, "jitter_s": 0.02}
V2X_PROFILES: Mapping[str, ChannelSpec] = MappingProxyType(
    {
        "ideal": ChannelSpec(generation=Generation(mode="every_step"), track_max_age_s=0.0),
        "typical": ChannelSpec.model_validate({**_BASE, "loss": {"model": "bernoulli", "probability": 0.05}}),
        "lossy": ChannelSpec.model_validate({**_BASE, "loss": {"model": "bernoulli", "probability": 0.3}}),
        "bursty": ChannelSpec.model_validate(
            {
                **_BASE,
                "loss": {
                    "model": "gilbert_elliott",
                    "p_good_to_bad": 0.02,
                    "p_bad_to_good": 0.2,
                    "loss_good": 0.01,
                    "loss_bad": 0.8,
                },
            }
        ),
        "congested": ChannelSpec.model_validate(
            {
                **_BASE,
                "latency_s": 0.3,
                "jitter_s": 0.05,
                "loss": {"model": "distance", "d50_m": 60.0, "scale_m": 15.0},
            }
        ),
        "noisy": ChannelSpec.model_validate({**_BASE, "rsu_position_sigma_m": 0.5, "rsu_speed_sigma_mps": 0.3}),
        "etsi": ChannelSpec(generation=Generation(mode="etsi_vam"), latency_s=0.1),
    }
)
"""The named channel profiles (values and their sources: docs/models.md, V2X)."""


def resolve_channel(channel: str | ChannelSpec, profiles: Mapping[str, ChannelSpec] | None = None) -> ChannelSpec:
    """The spec of a channel given by profile name (user `profiles` first, then `V2X_PROFILES`) or inline."""
    if isinstance(channel, ChannelSpec):
        return channel
    for table in (profiles or {}, V2X_PROFILES):
        if channel in table:
            return table[channel]
    known = sorted({*V2X_PROFILES, *(profiles or {})})
    raise UserInputError(f"v2x.channel: unknown channel profile {channel!r}; expected one of: {', '.join(known)}")


def check_channel(value: Any) -> str | ChannelSpec:
    """Validate a scenario's `v2x.channel`: a known profile name or a channel mapping (pydantic wrap helper)."""
    if isinstance(value, str):
        if value not in V2X_PROFILES:
            raise ValueError(f"unknown channel profile {value!r}; expected one of: {', '.join(sorted(V2X_PROFILES))}")
        return value
    if isinstance(value, ChannelSpec):
        return value
    if not isinstance(value, dict):
        raise ValueError("expected a profile name or a mapping of channel fields")
    return ChannelSpec.model_validate(value)


def load_profiles(path: str | Path) -> dict[str, ChannelSpec]:
    """Read user channel profiles: a YAML mapping of profile name → channel fields (as in `v2x.channel`)."""
    path = Path(path)
    data = read_yaml_file(path, "profile")
    if not isinstance(data, dict) or not data:
        raise UserInputError(f"{path}: expected a mapping of profile names to channel fields")
    profiles: dict[str, ChannelSpec] = {}
    problems: list[str] = []
    for name, fields in data.items():
        if not isinstance(name, str) or not name:
            problems.append(f"  {name!r}: a profile name must be a non-empty string")
        elif name in V2X_PROFILES:
            problems.append(f"  {name}: is a built-in profile; choose another name")
        elif not isinstance(fields, dict):
            problems.append(f"  {name}: expected a mapping of channel fields")
        else:
            try:
                profiles[name] = ChannelSpec.model_validate(fields)
            except ValidationError as error:
                for item in error.errors(include_url=False):
                    where = ".".join([name, *(str(p) for p in item["loc"])])
                    problems.append(f"  {where}: {error_message(item)}")
    if problems:
        raise UserInputError("\n".join([f"{path}: invalid channel profiles", *problems]))
    return profiles
