// dh3 web console: the hands live from /api/stream (Server-Sent Events read
// with fetch, so the bearer token can go in a header when viewing needs it),
// commands as POST /api/hands/SERVICE/BUS/ID/COMMAND. No libraries.
"use strict";

const LOG_LIMIT = 500;
const rows = new Map();  // "svc/bus0/1" -> {row, controls, status}
let token = sessionStorage.getItem("dh3-token") || "";

function headers(extra) {
  const h = Object.assign({}, extra || {});
  if (token) h.Authorization = "Bearer " + token;
  return h;
}

function setConnection(text) {
  document.getElementById("connection").textContent = text;
}

function timeOfDay(ns) {
  if (!ns) return "never";
  const d = new Date(Number(BigInt(ns) / 1000000n));
  const pad = (n, w) => String(n).padStart(w || 2, "0");
  return pad(d.getHours()) + ":" + pad(d.getMinutes()) + ":" + pad(d.getSeconds()) + "." +
         pad(d.getMilliseconds(), 3);
}

function numberOrDash(n) { return n === null || n === undefined || n < 0 ? "-" : String(n); }

function field(row, name) { return row.querySelector('[data-field="' + name + '"]'); }

function handRows(status) {
  let entry = rows.get(status.hand);
  if (entry) return entry;
  const template = document.getElementById("hand-rows").content.cloneNode(true);
  const [row, controls] = template.querySelectorAll("tr");
  row.dataset.hand = status.hand;
  controls.dataset.controls = status.hand;
  controls.querySelectorAll("button[data-command]").forEach((button) => {
    button.addEventListener("click", () => runCommand(status.hand, button, controls));
    button.setAttribute("aria-label", button.textContent + " " + status.hand);
  });
  // Rows sorted by address, so hands keep their place.
  const body = document.querySelector("#hands tbody");
  const after = [...rows.keys()].sort().find((key) => key > status.hand);
  const before = after ? rows.get(after).row : null;
  body.insertBefore(row, before);
  body.insertBefore(controls, before);
  entry = {row, controls, status: null};
  rows.set(status.hand, entry);
  document.getElementById("no-hands").hidden = true;
  return entry;
}

function showStatus(s) {
  const entry = handRows(s);
  const last = entry.status;
  if (last && s.update_seq < last.update_seq && BigInt(s.timestamp_ns) < BigInt(last.timestamp_ns) &&
      !s.service_lost) {
    return;  // an older sample (a snapshot after the live one); a restarted service counts anew
  }
  entry.status = s;
  const r = entry.row;
  field(r, "hand").textContent = s.hand + (s.name ? " (" + s.name + ")" : "");
  field(r, "online").textContent = s.online ? "online" : (s.service_lost ? "OFFLINE (service lost)" : "OFFLINE");
  r.classList.toggle("offline", !s.online);
  field(r, "initialized").textContent = s.initialized ? "yes" : "NO";
  field(r, "position").textContent = numberOrDash(s.position) + " / " + numberOrDash(s.target_position);
  field(r, "grip").textContent = s.grip;
  field(r, "force").textContent = s.closing_force + " / " + s.opening_force;
  field(r, "rotation").textContent = numberOrDash(s.rotation) + " / " + numberOrDash(s.rotation_target) +
                                     " " + s.rotation_state;
  field(r, "lease").textContent = s.lease_holder ? "held by " + s.lease_holder : "free";
  const error = field(r, "last_error");
  error.textContent = s.last_error === "OK" ? "none" : "Error " + s.last_error + ": " + s.last_error_message;
  error.classList.toggle("error", s.last_error !== "OK");
  field(r, "read_at").textContent = timeOfDay(s.read_at_ns);
}

function showEvent(e) {
  const log = document.getElementById("log");
  const item = document.createElement("li");
  item.className = e.kind.toLowerCase();
  item.dataset.hand = e.hand;
  let text = timeOfDay(e.timestamp_ns) + " " + e.hand + (e.name ? " (" + e.name + ")" : "") + " " +
             e.kind + " position " + (e.position === null ? "- (not read yet)" : e.position) +
             " target " + numberOrDash(e.target) + " value " + e.value;
  if (e.message) text += ": " + e.message;
  item.textContent = text;
  log.insertBefore(item, log.firstChild);
  while (log.children.length > LOG_LIMIT) log.removeChild(log.lastChild);
}

function inputValue(controls, name) {
  const input = controls.querySelector('[data-input="' + name + '"]');
  return Number(input.value);
}

/// The body of each command, from the hand's fields.
function commandBody(command, controls) {
  switch (command) {
    case "move":
    case "release":
      return {position: inputValue(controls, "position")};
    case "rotate":
      return {rotation: inputValue(controls, "rotation")};
    case "grasp":
      return {force: inputValue(controls, "force")};
    case "acquire-lease":
      return {ttl_ms: Math.round(inputValue(controls, "ttl") * 1000)};
    default:
      return {};
  }
}

function describeReply(command, reply, httpStatus) {
  if (reply.ok) {
    let text = command + ": OK";
    if (reply.grasp) text += " " + reply.grasp + " at position " + reply.value;
    if (reply.lease_holder) text += " (lease holder " + reply.lease_holder + ")";
    return {text, error: false};
  }
  return {text: "Error in " + command + " (HTTP " + httpStatus + " " + reply.code + "): " + reply.message,
          error: true};
}

async function runCommand(hand, button, controls) {
  const command = button.dataset.command;
  const result = field(rows.get(hand).row, "result");
  button.setAttribute("aria-busy", "true");
  result.textContent = command + ": sent…";
  result.classList.remove("error");
  let described;
  try {
    const path = "/api/hands/" + hand.split("/").map(encodeURIComponent).join("/") + "/" + command;
    const response = await fetch(path, {
      method: "POST",
      headers: headers({"Content-Type": "application/json"}),
      body: JSON.stringify(commandBody(command, controls)),
    });
    const reply = await response.json();
    described = describeReply(command, reply, response.status);
  } catch (err) {
    described = {text: "Error in " + command + ": no answer from dh3-web (" + err.message + ")", error: true};
  }
  button.removeAttribute("aria-busy");
  result.textContent = described.text;
  result.classList.toggle("error", described.error);
}

function dispatch(name, data) {
  if (name === "status") showStatus(JSON.parse(data));
  else if (name === "event") showEvent(JSON.parse(data));
  else if (name === "ready") setConnection("Live: updates arrive as the hands change.");
}

/// Reads the SSE stream; returns when it ends.
async function readStream() {
  const response = await fetch("/api/stream", {headers: headers({Accept: "text/event-stream"})});
  if (response.status === 401) {
    setConnection("Error: viewing needs the bearer token; enter it above.");
    return false;
  }
  if (!response.ok || !response.body) throw new Error("HTTP " + response.status);
  // A stream starts with the last events again: the log is rebuilt from them.
  document.getElementById("log").replaceChildren();
  const reader = response.body.getReader();
  const decoder = new TextDecoder();
  let buffer = "";
  for (;;) {
    const {value, done} = await reader.read();
    if (done) return true;
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
    try {
      retry = await readStream();
      if (retry) setConnection("Error: the stream ended; reconnecting…");
    } catch (err) {
      setConnection("Error: no connection to dh3-web (" + err.message + "); reconnecting…");
    }
    if (!retry) break;
    await new Promise((resolve) => setTimeout(resolve, 1000));
  }
  streaming = false;
}

function showTokenState() {
  document.getElementById("token-state").textContent =
      token ? "Token set for this tab." : "No token: the hands can be watched, not driven.";
}

document.getElementById("token-form").addEventListener("submit", (event) => {
  event.preventDefault();
  token = document.getElementById("token").value.trim();
  document.getElementById("token").value = "";
  if (token) sessionStorage.setItem("dh3-token", token);
  else sessionStorage.removeItem("dh3-token");
  showTokenState();
  streamForever();
});

showTokenState();
streamForever();
