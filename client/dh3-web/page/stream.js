// The hands live from /api/stream: Server-Sent Events read with fetch, so
// the bearer token can go in a header when viewing needs it; a stream that
// goes silent is opened again.
"use strict";

function dispatch(name, data) {
  if (name === "status") showStatus(JSON.parse(data));
  else if (name === "event") showEvent(JSON.parse(data));
  else if (name === "service") showService(JSON.parse(data));
  else if (name === "alarms") showAlarmList(JSON.parse(data));
  else if (name === "ready") { stream.open = true; refresh(); }
  if (name === "status") showCommissioning();
}

/// Reads the SSE stream; returns true when it ended and should be opened again.
async function readStream() {
  const abort = new AbortController();
  const watchdog = setInterval(() => {
    if (performance.now() - stream.lastChunk > SILENT_MS) abort.abort();
  }, 1000);
  stream.lastChunk = performance.now();
  try {
    const response = await fetch("/api/stream",
                                 {headers: headers({Accept: "text/event-stream"}), signal: abort.signal});
    if (response.status === 401) {
      stream.error = "viewing needs the bearer token; enter it above";
      return false;
    }
    if (!response.ok || !response.body) {
      const reply = await response.json().catch(() => ({message: "HTTP " + response.status}));
      const error = new Error(reply.message || "HTTP " + response.status);
      error.retryAfter = Number(response.headers.get("Retry-After")) || 1;  // 503: dh3-web is full
      throw error;
    }
    // A stream starts with the last events again: the log is rebuilt from them.
    document.getElementById("log").replaceChildren();
    await readEvents(response.body.getReader());
    stream.error = "the stream ended; reconnecting…";
    return true;
  } finally {
    clearInterval(watchdog);
    stream.open = false;
    refresh();
  }
}

async function readEvents(reader) {
  const decoder = new TextDecoder();
  let buffer = "";
  for (;;) {
    const {value, done} = await reader.read();
    if (done) return;
    stream.lastChunk = performance.now();
    buffer += decoder.decode(value, {stream: true});
    let end;
    while ((end = buffer.indexOf("\n\n")) >= 0) {
      const block = buffer.slice(0, end);
      buffer = buffer.slice(end + 2);
      let name = "message";
      const data = [];
      for (const line of block.split("\n")) {
        if (line.startsWith("event: ")) name = line.slice(7);
        else if (line.startsWith("data: ")) data.push(line.slice(6));
      }
      if (data.length) dispatch(name, data.join("\n"));
    }
  }
}

let streaming = false;

async function streamForever() {
  if (streaming) return;
  streaming = true;
  for (;;) {
    let retry = true;
    let seconds = 1;
    try {
      retry = await readStream();
    } catch (err) {
      stream.error = "no stream from dh3-web (" + (err.name === "AbortError" ? "silent" : err.message) +
                     "); reconnecting…";
      seconds = err.retryAfter || 1;
    }
    refresh();
    if (!retry) break;
    await new Promise((resolve) => setTimeout(resolve, seconds * 1000));
  }
  streaming = false;
}
