// A job's progress events, live: GET v1/jobs/{id}/events as NDJSON (one JSON object per line, blank lines are
// heartbeats) read with fetch() and a stream reader, because EventSource cannot send the Authorization header.
// Every event from the first is delivered once, in order, up to `end`; a dropped connection is resumed after the
// last event received (Last-Event-ID), as the Python client does.

import {ApiError, errorFrom, headers} from "./api.js";

const BACKOFF_MS = [500, 1000, 2000, 4000, 8000];

function sleep(ms, signal) {
  return new Promise((resolve) => {
    const timer = setTimeout(resolve, ms);
    if (signal) signal.addEventListener("abort", () => { clearTimeout(timer); resolve(); }, {once: true});
  });
}

// Calls onEvent(event) for every event; resolves with the `end` event, or null when the stream closed for good
// without one (the server shut down and did not come back, the job was deleted). Rejects with an ApiError for an
// answer that will not change by retrying (401, 404). Aborting `signal` ends it quietly (resolves null).
// onNote(text) hears about reconnections.
export async function followEvents(jobId, onEvent, {signal, onNote = () => {}} = {}) {
  let lastSeq = 0;
  let failures = 0;
  while (!(signal && signal.aborted)) {
    const h = headers({"Accept": "application/x-ndjson"});
    if (lastSeq > 0) h["Last-Event-ID"] = String(lastSeq);
    let progressed = false;
    try {
      const response = await fetch(`v1/jobs/${encodeURIComponent(jobId)}/events`,
                                   {headers: h, signal, cache: "no-store"});
      if (!response.ok) {
        const error = await errorFrom(response);
        if (response.status !== 503) throw error;  // 503: too many streams or the server is starting: retry
        throw Object.assign(error, {retry: true});
      }
      const reader = response.body.getReader();
      const decoder = new TextDecoder();
      let pending = "";
      for (;;) {
        const {value, done} = await reader.read();
        if (done) break;
        pending += decoder.decode(value, {stream: true});
        let newline;
        while ((newline = pending.indexOf("\n")) >= 0) {
          const line = pending.slice(0, newline).trim();
          pending = pending.slice(newline + 1);
          if (!line) continue;  // heartbeat
          let event;
          try {
            event = JSON.parse(line);
          } catch (e) {
            continue;  // never expected; a torn line is resent after a reconnection
          }
          if (typeof event.seq === "number") {
            if (event.seq <= lastSeq) continue;
            lastSeq = event.seq;
          }
          progressed = true;
          failures = 0;
          onEvent(event);
          if (event.type === "end") {
            reader.cancel().catch(() => {});
            return event;
          }
        }
      }
    } catch (e) {
      if (signal && signal.aborted) return null;
      if (e instanceof ApiError && !e.retry) throw e;
    }
    if (signal && signal.aborted) return null;
    if (!progressed) failures += 1;
    if (failures > BACKOFF_MS.length) return null;
    const wait = BACKOFF_MS[Math.min(Math.max(failures - 1, 0), BACKOFF_MS.length - 1)];
    onNote(`stream closed after event ${lastSeq}; reconnecting in ${wait / 1000} s`);
    await sleep(wait, signal);
  }
  return null;
}
