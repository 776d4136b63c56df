"""Reading a run's MCAP log back: its metadata, poses, modes, events and moving obstacles, also
from a file whose writer was killed (every complete chunk is kept)."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO, cast

import numpy as np
from mcap import records as mr
from mcap.exceptions import EndOfFile
from mcap.stream_reader import StreamReader
from mcap_protobuf.decoder import DecoderFactory

from vplane_mj.logs.writer import EVENTS_DATA_TOPIC, MOVING_TOPIC, SUMMARY_METADATA_NAME
from vplane_mj.planning.protocol.events import EVENT_POINTS, EventKind


@dataclass(frozen=True)
class LoggedEvent:
    """An event as the log keeps it: simulated time (s), kind, text and named points (m)."""

    time_s: float
    kind: EventKind
    text: str
    data: dict[str, tuple[float, float]] = field(default_factory=dict)

    @classmethod
    def from_json(cls, log_time_ns: int, record: dict[str, Any]) -> LoggedEvent:
        data = {key: (float(record[key][0]), float(record[key][1])) for key in EVENT_POINTS if key in record}
        return cls(log_time_ns / 1e9, EventKind(record["kind"]), str(record["text"]), data)


@dataclass(frozen=True)
class LogMessage:
    """One decoded message: its topic, schema name, log time (ns) and decoded content.

    Protobuf messages are decoded to their generated protobuf classes (fields as in
    the `foxglove.*` schemas), JSON messages to Python dicts.
    """

    topic: str
    schema: str
    log_time_ns: int
    message: Any


@dataclass
class LogContents:
    """What `read_log` gets back from a log file.

    `metadata`: metadata record name -> its key/value strings; `times_ns`, `positions`
    (N, 2) and `yaws` (N,): the `/robot/pose` messages; `modes`: planner mode per
    `/metrics` message; `events`: the events of `/run/events`, in order; `topics`: topic
    -> (schema name, message count) over every message read; `complete`: whether the
    file ended with its footer (False for a file whose writer was killed);
    `obstacle_times_ns` (M,) and `obstacle_places` (M, count, 2; m): the `/world/moving`
    messages, where the moving obstacles stood, in each message's order of entities (the
    scenario's `world.moving`); none in a world without any. `messages`: the decoded messages
    of the topics `read_log` was asked to keep, in file order.
    """

    metadata: dict[str, dict[str, str]]
    times_ns: np.ndarray
    positions: np.ndarray
    yaws: np.ndarray
    modes: list[str]
    events: list[LoggedEvent]
    topics: dict[str, tuple[str, int]]
    complete: bool = True
    message_encodings: dict[str, str] = field(default_factory=dict)
    obstacle_times_ns: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    obstacle_places: np.ndarray = field(default_factory=lambda: np.empty((0, 0, 2)))
    messages: list[LogMessage] = field(default_factory=list)

    def obstacles_at_poses(self) -> np.ndarray | None:
        """Where the moving obstacles stood at each pose of `times_ns` (N, count, 2; m): the last
        `/world/moving` message at or before it (the first before the first); None without any."""
        if len(self.obstacle_times_ns) == 0:
            return None
        latest = np.searchsorted(self.obstacle_times_ns, self.times_ns, side="right") - 1
        return self.obstacle_places[np.maximum(latest, 0)]

    @property
    def summary(self) -> dict | None:
        """The run summary stored at close, or None (e.g. the writer was killed)."""
        record = self.metadata.get(SUMMARY_METADATA_NAME)
        return None if record is None else json.loads(record["json"])


class _StrictStream:
    """A read-only stream that fails on a short read instead of returning fewer bytes.

    The mcap stream reader trusts each record's length prefix; on a cut-off file the
    last record's read comes back short, and this turns that into `EndOfFile`, so an
    incomplete record is never parsed.
    """

    def __init__(self, raw: BinaryIO):
        self._raw = raw

    def read(self, size: int = -1) -> bytes:
        data = self._raw.read(size)
        if size is not None and size >= 0 and len(data) < size:
            raise EndOfFile()
        return data


class _RecordScan:
    """Sequentially scan a (possibly truncated) MCAP file, tracking schemas, channels, metadata."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.metadata: dict[str, dict[str, str]] = {}
        self.complete = False

    def messages(self) -> Iterator[tuple[Any, Any, Any]]:
        """(schema, channel, message record) for every message in a complete record."""
        schemas: dict[int, Any] = {}
        channels: dict[int, Any] = {}
        with open(self.path, "rb") as raw:
            # The reader only calls read(), which is all a _StrictStream has.
            reader = StreamReader(cast(BinaryIO, _StrictStream(raw)), validate_crcs=True)
            records = reader.records
            while True:
                try:
                    record = next(records)
                except StopIteration:
                    return
                except Exception:  # a cut-off (EndOfFile) or damaged tail: keep what came before
                    return
                if isinstance(record, mr.Message):
                    channel = channels.get(record.channel_id)
                    if channel is not None:
                        yield schemas.get(channel.schema_id), channel, record
                elif isinstance(record, mr.Schema):
                    schemas[record.id] = record
                elif isinstance(record, mr.Channel):
                    channels[record.id] = record
                elif isinstance(record, mr.Metadata):
                    self.metadata[record.name] = dict(record.metadata)
                elif isinstance(record, mr.Footer):
                    self.complete = True


class _Decoders:
    """Message decoders by (encoding, schema id): protobuf via mcap-protobuf-support, JSON."""

    def __init__(self) -> None:
        self._factory = DecoderFactory()
        self._cache: dict[tuple[str, int], Any] = {}

    def decode(self, schema: Any, channel: Any, data: bytes) -> Any:
        if channel.message_encoding == "json":
            return json.loads(data)
        key = (channel.message_encoding, channel.schema_id)
        decoder = self._cache.get(key)
        if decoder is None:
            decoder = self._factory.decoder_for(channel.message_encoding, schema)
            if decoder is None:
                raise ValueError(f"no decoder for {channel.message_encoding!r} on {channel.topic}")
            self._cache[key] = decoder
        return decoder(data)


def iter_messages(path: Path, topics: tuple[str, ...] | None = None) -> Iterator[LogMessage]:
    """Decoded messages of `topics` (all when None) in file order; tolerates a cut-off file."""
    decoders = _Decoders()
    for schema, channel, record in _RecordScan(path).messages():
        if topics is not None and channel.topic not in topics:
            continue
        yield LogMessage(
            topic=channel.topic,
            schema=schema.name if schema is not None else "",
            log_time_ns=record.log_time,
            message=decoders.decode(schema, channel, record.data),
        )


def read_log(path: Path, keep: tuple[str, ...] = ()) -> LogContents:
    """Read a log written by `McapLog`, also one whose writer was killed; with the decoded
    messages of the topics `keep` in `messages` (read in the same pass).

    The file is read front to back with the `mcap` package's `StreamReader` (never
    seeking to the summary section, which a killed writer never wrote), through a
    stream that treats a short read as the end of the file. Every complete record
    before the cut is kept: all chunks finished by a flush (about once per simulated
    second) and the metadata written at the start; reading stops quietly at the
    first incomplete or damaged record (chunk CRCs are checked). `complete` tells
    whether the footer was reached. Protobuf messages are decoded with
    `mcap_protobuf.decoder.DecoderFactory`, `/metrics` and `/run/events` as JSON.
    """
    scan = _RecordScan(Path(path))
    decoders = _Decoders()
    counts: dict[str, list] = {}
    encodings: dict[str, str] = {}
    times: list[int] = []
    poses: list[tuple[float, float, float]] = []
    modes: list[str] = []
    events: list[LoggedEvent] = []
    obstacle_times: list[int] = []
    obstacle_places: list[list[tuple[float, float]]] = []
    kept: list[LogMessage] = []
    read = (*keep, "/robot/pose", "/metrics", MOVING_TOPIC, EVENTS_DATA_TOPIC)
    for schema, channel, record in scan.messages():
        topic = channel.topic
        schema_name = schema.name if schema is not None else ""
        entry = counts.setdefault(topic, [schema_name, 0])
        entry[1] += 1
        encodings[topic] = channel.message_encoding
        if topic not in read:
            continue
        message = decoders.decode(schema, channel, record.data)
        if topic == "/robot/pose":
            pose = message.pose
            q = pose.orientation
            times.append(record.log_time)
            poses.append((pose.position.x, pose.position.y, 2 * math.atan2(q.z, q.w)))
        elif topic == "/metrics":
            modes.append(str(message.get("mode", "")))
        elif topic == MOVING_TOPIC:
            obstacle_times.append(record.log_time)
            obstacle_places.append(entity_centres(message))
        elif topic == EVENTS_DATA_TOPIC:
            events.append(LoggedEvent.from_json(record.log_time, message))
        if topic in keep:
            kept.append(LogMessage(topic, schema_name, record.log_time, message))
    pose_array = np.array(poses, dtype=float).reshape(-1, 3)
    return LogContents(
        metadata=scan.metadata,
        times_ns=np.array(times, dtype=np.int64),
        positions=pose_array[:, :2].copy(),
        yaws=pose_array[:, 2].copy(),
        modes=modes,
        events=events,
        topics={topic: (name, count) for topic, (name, count) in counts.items()},
        complete=scan.complete,
        message_encodings=encodings,
        obstacle_times_ns=np.array(obstacle_times, dtype=np.int64),
        obstacle_places=np.array(obstacle_places, dtype=float).reshape(len(obstacle_times), -1, 2)
        if obstacle_times
        else np.empty((0, 0, 2)),
        messages=kept,
    )


def entity_centres(update: Any) -> list[tuple[float, float]]:
    """The centre (x, y; m) of each entity of a decoded SceneUpdate, in order: its first cylinder's
    or cube's (a moving obstacle is one piece)."""
    centres = []
    for entity in update.entities:
        position = (entity.cylinders or entity.cubes)[0].pose.position
        centres.append((position.x, position.y))
    return centres
