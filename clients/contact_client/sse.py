"""Server-Sent Events as contactd sends them (docs/server.md, "Events")."""
import json

from .errors import BadAnswer, one_line

MAX_EVENT_BYTES = 16 << 20


def read_sse(resp):
    """Server-Sent Events from an http.client response: yields each event's data as a dict (the SSE `id` and
    `event` fields repeat the object's seq and type). Comments (heartbeats) are skipped. Data that is not a JSON
    object raises BadAnswer (the stream is not contactd's)."""
    data, event_type, size = [], None, 0
    while True:
        line = resp.readline(MAX_EVENT_BYTES + 1)
        if not line:
            return
        size += len(line)
        if size > MAX_EVENT_BYTES:
            raise BadAnswer(f"an event of the progress stream is larger than {MAX_EVENT_BYTES} bytes")
        line = line.decode("utf-8", "replace").rstrip("\r\n")
        if line == "":
            if data:
                try:
                    obj = json.loads("\n".join(data))
                except (ValueError, RecursionError):
                    raise BadAnswer("the progress stream sent an event that is not JSON: "
                                    f"{one_line(' '.join(data))[:80]!r}") from None
                if not isinstance(obj, dict):
                    raise BadAnswer(f"the progress stream sent an event that is a JSON {type(obj).__name__}, "
                                    "not an object")
                if not isinstance(obj.get("type"), str):
                    obj["type"] = event_type
                yield obj
            data, event_type, size = [], None, 0
            continue
        if line.startswith(":"):
            continue
        key, _, value = line.partition(":")
        value = value[1:] if value.startswith(" ") else value
        if key == "data":
            data.append(value)
        elif key == "event":
            event_type = value
