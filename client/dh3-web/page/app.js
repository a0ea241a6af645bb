// dh3 web console: the hands live from /api/stream (Server-Sent Events read
// with fetch, so the bearer token can go in a header when viewing needs it),
// commands as POST /api/hands/SERVICE/BUS/ID/COMMAND. No libraries.
//
// What the page shows as live is live: a hand whose service is lost, whose
// values are older than STALE_MS, or a stream that went quiet is marked at
// once; and no command leaves the page from a field that does not hold a
// valid value.
"use strict";

const LOG_LIMIT = 500;
/// Values older than this are marked stale. A hand that changes is published
/// at once; one that does not is published again with its new read time every
/// dds.status_refresh_ms of its service (5 s by default), so a few seconds
/// more than that is the first sign of a service or hand that went quiet.
const STALE_MS = 8000;
/// dh3-web sends the services every 2 s when nothing else happens: a stream
/// silent for longer than this is stalled and is opened again.
const SILENT_MS = 6000;
/// The fields a command takes its value from, with the API's ranges.
const FIELDS = {
  position: {label: "Position", min: 0, max: 100},
  rotation: {label: "Rotation", min: 0, max: 100},
  force: {label: "Force", min: 20, max: 100},
  ttl: {label: "Lease (s)", min: 1, max: 600},
};
const COMMAND_FIELD = {move: "position", release: "position", rotate: "rotation", grasp: "force",
                       "acquire-lease": "ttl"};

const hands = new Map();     // "svc/bus0/1" -> {card, status, arrived, readAge}
const services = new Map();  // name -> service info
let token = sessionStorage.getItem("dh3-token") || "";
/// "unknown" (not checked yet), "checking", "accepted", "wrong", "disabled", "none"
let tokenState = token ? "unknown" : "none";
let consoleName = "";        // how the services show this console as a lease holder
let stream = {open: false, lastChunk: 0, error: "connecting…"};

function headers(extra) {
  const h = Object.assign({}, extra || {});
  if (token) h.Authorization = "Bearer " + token;
  return h;
}

function pad(n, w) { return String(n).padStart(w || 2, "0"); }

function timeOfDay(ms) {
  const d = new Date(ms);
  return pad(d.getHours()) + ":" + pad(d.getMinutes()) + ":" + pad(d.getSeconds()) + "." +
         pad(d.getMilliseconds(), 3);
}

function nsToMs(ns) { return Number(BigInt(ns) / 1000000n); }

function numberOrDash(n) { return n === null || n === undefined || n < 0 ? "-" : String(n); }

function field(card, name) { return card.querySelector('[data-field="' + name + '"]'); }

/// With DDS Security the service adds the certificate's subject: " (CN=...)".
function isThisConsole(holder) {
  return consoleName !== "" && (holder === consoleName || holder.startsWith(consoleName + " ("));
}

/// "dh3ctl@cell-pc" -> "dh3ctl on host cell-pc"; this console's own: "this console".
function holderInWords(holder) {
  if (!holder) return "";
  if (isThisConsole(holder)) return "this console";
  const m = /^(.*)@([^@\s(]+)(.*)$/.exec(holder);
  return m ? m[1] + " on host " + m[2] + m[3] : holder;
}

function handCard(address) {
  let entry = hands.get(address);
  if (entry) return entry;
  const card = document.getElementById("hand-card").content.firstElementChild.cloneNode(true);
  card.dataset.hand = address;
  card.querySelectorAll("button[data-command]").forEach((button) => {
    button.addEventListener("click", () => runCommand(address, button));
    button.setAttribute("aria-label", button.textContent + " " + address);
  });
  card.querySelectorAll("input[data-input]").forEach((input) => {
    input.addEventListener("input", () => checkField(card, input.dataset.input));
  });
  // Cards sorted by address, so hands keep their place.
  const after = [...hands.keys()].sort().find((key) => key > address);
  document.getElementById("hands").insertBefore(card, after ? hands.get(after).card : null);
  entry = {card, status: null, arrived: 0, readAge: Infinity};
  hands.set(address, entry);
  document.getElementById("no-hands").hidden = true;
  return entry;
}

function showStatus(s) {
  const entry = handCard(s.hand);
  const last = entry.status;
  if (last && s.update_seq < last.update_seq && BigInt(s.timestamp_ns) < BigInt(last.timestamp_ns) &&
      !s.service_lost) {
    return;  // an older sample (a snapshot after the live one); a restarted service counts anew
  }
  entry.status = s;
  entry.arrived = performance.now();
  // How old the values already were when the sample was published: both on
  // the service's clock, so the browser's clock need not agree with it.
  entry.readAge = s.read_at_ns === "0" || !s.read_at_ns ? Infinity
      : Math.max(0, nsToMs(s.timestamp_ns) - nsToMs(s.read_at_ns));
  const c = entry.card;
  field(c, "hand").textContent = s.hand + (s.name ? " (" + s.name + ")" : "");
  field(c, "initialized").textContent = s.initialized ? "yes" : "NO";
  field(c, "position").textContent = numberOrDash(s.position) + " / " + numberOrDash(s.target_position);
  c.querySelector('[data-gauge="position"]').value = Math.max(0, s.position);
  field(c, "grip").textContent = s.grip;
  field(c, "force").textContent = numberOrDash(s.closing_force) + " / " + numberOrDash(s.opening_force);
  field(c, "rotation").textContent = numberOrDash(s.rotation) + " / " + numberOrDash(s.rotation_target) +
                                     " " + s.rotation_state;
  c.querySelector('[data-gauge="rotation"]').value = Math.max(0, s.rotation);
  const error = field(c, "last_error");
  error.textContent = s.last_error === "OK" ? "none" : "Error " + s.last_error + ": " + s.last_error_message;
  error.classList.toggle("error", s.last_error !== "OK");
  field(c, "read_at").textContent = s.read_at_ns && s.read_at_ns !== "0"
      ? timeOfDay(nsToMs(s.read_at_ns)) : "never";
  showLiveness(entry);
}

function serviceLost(status) {
  const info = services.get(status.service);
  return status.service_lost || (info !== undefined && !info.ready);
}

/// The hand's state in words, and whether its values are live.
function liveness(entry) {
  const s = entry.status;
  if (serviceLost(s)) return {text: "LOST: service " + s.service + " lost; last known values", live: false};
  if (!s.online) return {text: "OFFLINE: the hand does not answer", live: false};
  const age = performance.now() - entry.arrived + entry.readAge;
  if (!stream.open) return {text: "NOT LIVE: no stream from dh3-web; last known values", live: false};
  if (age > STALE_MS) {
    return {text: "STALE: values " + (age === Infinity ? "never read" : Math.round(age / 1000) + " s old"),
            live: false};
  }
  return {text: "online", live: true};
}

/// Why this hand takes no commands now, or "" when it does.
function blockReason(s) {
  if (tokenState === "disabled") return "this dh3-web takes no commands (started without --token-file)";
  if (tokenState === "wrong") return "the token is wrong; enter the right one above";
  if (tokenState === "none") return "commands need the token; enter it above";
  if (tokenState !== "accepted") return "checking the token…";
  if (serviceLost(s)) return "its service is lost";
  if (!s.online) return "the hand is offline";
  if (s.lease_holder && !isThisConsole(s.lease_holder)) {
    return "held by " + holderInWords(s.lease_holder) + " (its lease)";
  }
  return "";
}

function showLiveness(entry) {
  const c = entry.card;
  const state = liveness(entry);
  const s = entry.status;
  const online = field(c, "online");
  if (online.textContent !== state.text) online.textContent = state.text;
  c.classList.toggle("not-live", !state.live);
  const lease = s.lease_holder ? "held by " + holderInWords(s.lease_holder) : "free";
  if (field(c, "lease").textContent !== lease) field(c, "lease").textContent = lease;
  const reason = blockReason(s);
  const blocked = field(c, "blocked");
  const words = reason ? "Commands off: " + reason : "";
  if (blocked.textContent !== words) blocked.textContent = words;
  blocked.hidden = !reason;
  c.querySelectorAll("button[data-command]").forEach((button) => {
    button.disabled = reason !== "";
    if (reason) button.title = reason; else button.removeAttribute("title");
  });
}

function showConnection() {
  const now = performance.now();
  const lost = new Set([...services.values()].filter((info) => !info.ready).map((info) => info.service));
  const stale = [];
  hands.forEach((entry, address) => {
    if (!entry.status) return;
    if (entry.status.service_lost) lost.add(entry.status.service);
    else if (entry.status.online && !liveness(entry).live) stale.push(address);
  });
  let text;
  if (!stream.open) text = "NOT LIVE: " + stream.error;
  else if (now - stream.lastChunk > SILENT_MS) text = "NOT LIVE: no news from dh3-web for " +
      Math.round((now - stream.lastChunk) / 1000) + " s";
  else if (lost.size) text = "NOT LIVE: service " + [...lost].join(", ") + " lost";
  else if (stale.length) text = "NOT LIVE: stale values from " + stale.join(", ");
  else text = "Live: updates arrive as the hands change.";
  const connection = document.getElementById("connection");
  if (connection.textContent !== text) connection.textContent = text;
  connection.className = text.startsWith("Live") ? "live" : "not-live";
}

function showService(info) {
  services.set(info.service, info);
  const list = document.getElementById("services");
  list.replaceChildren(...[...services.values()].map((s) => {
    const item = document.createElement("li");
    const buses = s.buses.map((b) => b.name + " (" + b.spec + ", link " + (b.link_up ? "up" : "DOWN") + ")");
    item.textContent = s.service + (s.ready ? ": ready" : ": LOST") + " on host " + (s.host || "?") +
        ", version " + (s.version || "?") + ", admin " + (s.admin_allowed ? "allowed" : "not allowed") +
        "; buses " + (buses.join(", ") || "none");
    item.className = s.ready ? "" : "error";
    return item;
  }));
}

function refresh() {
  showConnection();
  hands.forEach((entry) => { if (entry.status) showLiveness(entry); });
}

function showEvent(e) {
  const log = document.getElementById("log");
  const item = document.createElement("li");
  item.className = e.kind.toLowerCase();
  item.dataset.hand = e.hand;
  const when = e.timestamp_ns && e.timestamp_ns !== "0" ? nsToMs(e.timestamp_ns) : Date.now();
  let text = timeOfDay(when) + " " + e.hand + (e.name ? " (" + e.name + ")" : "") + " " + e.kind;
  if (["ARRIVED", "GRASPED", "MISSED", "DROPPED"].includes(e.kind)) {
    text += " position " + (e.position === null ? "not read yet" : e.position) + ", target " +
            numberOrDash(e.target);
  }
  if (e.kind === "GRASPED") text += ", force " + e.value;
  if (e.from_client) text += " (seen by dh3-web)";
  if (e.message) text += ": " + e.message;
  item.textContent = text;
  log.insertBefore(item, log.firstChild);
  while (log.children.length > LOG_LIMIT) log.removeChild(log.lastChild);
}

/// The field's whole number, or null with the reason shown beside the field.
function checkField(card, name) {
  const spec = FIELDS[name];
  const input = card.querySelector('[data-input="' + name + '"]');
  const text = input.value.trim();
  let problem = "";
  if (input.validity.badInput) problem = "not a number";
  else if (text === "") problem = "empty";
  else if (!/^-?\d+$/.test(text)) problem = "“" + text + "” is not a whole number";
  else if (Number(text) < spec.min || Number(text) > spec.max) problem = text + " is out of range";
  const error = card.querySelector('[data-error="' + name + '"]');
  error.textContent = problem ? "Error: " + problem + " (" + spec.min + "-" + spec.max + "); nothing sent" : "";
  if (problem) input.setAttribute("aria-invalid", "true"); else input.removeAttribute("aria-invalid");
  return problem ? null : Number(text);
}

/// The command's body from the hand's fields, or null if a field is not valid.
function commandBody(command, card) {
  const name = COMMAND_FIELD[command];
  if (!name) return {};
  const value = checkField(card, name);
  if (value === null) return null;
  switch (command) {
    case "move":
    case "release": return {position: value};
    case "rotate": return {rotation: value};
    case "grasp": return {force: value};
    default: return {ttl_ms: value * 1000};
  }
}

function describeReply(command, reply, httpStatus) {
  if (reply.ok) {
    let text = command + ": OK";
    if (reply.grasp) text += " " + reply.grasp + " at position " + reply.value;
    if (reply.lease_holder) text += " (lease held by " + holderInWords(reply.lease_holder) + ")";
    return {text, error: false};
  }
  return {text: "Error in " + command + " (HTTP " + httpStatus + " " + reply.code + "): " + reply.message,
          error: true};
}

/// POSTs a command; the reply in words.
async function send(address, command, body) {
  try {
    const path = "/api/hands/" + address.split("/").map(encodeURIComponent).join("/") + "/" + command;
    const response = await fetch(path, {
      method: "POST",
      headers: headers({"Content-Type": "application/json"}),
      body: JSON.stringify(body),
    });
    if (response.status === 401 && token) setTokenState("wrong");
    return describeReply(command, await response.json(), response.status);
  } catch (err) {
    return {text: "Error in " + command + ": no answer from dh3-web (" + err.message + ")", error: true};
  }
}

function showResult(address, described) {
  const result = field(hands.get(address).card, "result");
  result.textContent = described.text;
  result.classList.toggle("error", described.error);
}

async function runCommand(address, button) {
  const command = button.dataset.command;
  const card = hands.get(address).card;
  const body = commandBody(command, card);
  if (body === null) {
    showResult(address, {text: command + ": not sent (a field above is not valid)", error: true});
    return;
  }
  button.setAttribute("aria-busy", "true");
  showResult(address, {text: command + ": sent…", error: false});
  const described = await send(address, command, body);
  button.removeAttribute("aria-busy");
  showResult(address, described);
}

/// Stop to every hand the page shows, whatever their state: an offline hand
/// refuses it in words, and no hand is skipped on the page's judgement.
async function stopAll() {
  const result = document.getElementById("stop-all-result");
  const addresses = [...hands.keys()];
  if (!addresses.length) {
    result.textContent = "Stop all: no hands shown";
    return;
  }
  result.textContent = "Stop all: sent to " + addresses.length + " hands…";
  const replies = await Promise.all(addresses.map(async (address) => {
    const described = await send(address, "stop", {});
    showResult(address, described);
    return {address, described};
  }));
  const failed = replies.filter((r) => r.described.error);
  result.textContent = failed.length === 0
      ? "Stop all: every hand stopped (" + addresses.length + ")"
      : "Error: Stop all: " + (addresses.length - failed.length) + " of " + addresses.length +
        " stopped; not " + failed.map((r) => r.address).join(", ") + " (" + failed[0].described.text + ")";
  result.className = failed.length ? "error" : "ok";
}

function dispatch(name, data) {
  if (name === "status") showStatus(JSON.parse(data));
  else if (name === "event") showEvent(JSON.parse(data));
  else if (name === "service") showService(JSON.parse(data));
  else if (name === "ready") { stream.open = true; refresh(); }
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

function setTokenState(state, detail) {
  tokenState = state;
  const words = {
    none: "No token: the hands can be watched, not driven.",
    checking: "Checking the token…",
    accepted: "Token accepted: commands go to the hands.",
    wrong: "Error: the token is wrong (dh3-web refused it); commands are off.",
    disabled: "Error: this dh3-web takes no commands (started without --token-file).",
    unknown: "Error: the token could not be checked (" + (detail || "no answer") + "); commands are off.",
  };
  const shown = document.getElementById("token-state");
  shown.textContent = words[state];
  shown.className = state === "accepted" ? "ok" : (state === "none" || state === "checking" ? "" : "error");
  refresh();
}

/// Asks dh3-web whether the token is the right one, without moving anything.
async function checkToken() {
  if (!token) {
    setTokenState("none");
    return;
  }
  setTokenState("checking");
  try {
    const response = await fetch("/api/token", {headers: headers()});
    const reply = await response.json();
    if (response.ok) {
      consoleName = reply.console || "";
      setTokenState("accepted");
    } else {
      setTokenState(response.status === 403 ? "disabled" : (response.status === 401 ? "wrong" : "unknown"),
                    reply.message);
    }
  } catch (err) {
    setTokenState("unknown", err.message);
  }
}

async function loadConsoleName() {
  try {
    const response = await fetch("/api/health", {headers: headers()});
    if (response.ok) consoleName = (await response.json()).console || consoleName;
  } catch (err) {
    // The stream's own error says that dh3-web is not there.
  }
}

document.getElementById("token-form").addEventListener("submit", (event) => {
  event.preventDefault();
  token = document.getElementById("token").value.trim();
  document.getElementById("token").value = "";
  if (token) sessionStorage.setItem("dh3-token", token);
  else sessionStorage.removeItem("dh3-token");
  checkToken();
  streamForever();
});
document.getElementById("stop-all").addEventListener("click", stopAll);

setInterval(refresh, 500);
loadConsoleName();
checkToken();
streamForever();
