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
/// How often the page asks dh3-web for its own health.
const HEALTH_MS = 5000;
/// The fields a command takes its value from, with the API's ranges.
const FIELDS = {
  position: {label: "Position", min: 0, max: 100},
  rotation: {label: "Rotation", min: 0, max: 100},
  force: {label: "Force", min: 20, max: 100},
  ttl: {label: "Lease (s)", min: 1, max: 600},
  closing: {label: "Closing force", min: 20, max: 100},
  opening: {label: "Opening force", min: 20, max: 100},
  can_id: {label: "New CAN ID", min: 1, max: 255},
};
const COMMAND_FIELD = {move: "position", release: "position", rotate: "rotation", grasp: "force",
                       "acquire-lease": "ttl"};

const hands = new Map();     // "svc/bus0/1" -> {card, status, arrived, readAge}
const services = new Map();  // name -> service info
let token = sessionStorage.getItem("dh3-token") || "";
/// "unknown" (not checked yet), "checking", "accepted", "wrong", "disabled", "none"
let tokenState = token ? "unknown" : "none";
let consoleName = "";        // how the services show this console as a lease holder
let consoleHealth = null;    // dh3-web's /api/health
let healthError = "asking…"; // why there is no consoleHealth
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
  showStop(s);
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

/// Why no command leaves this console now, or "" when they do.
function tokenBlock() {
  if (tokenState === "disabled") return "this dh3-web takes no commands (started without --token-file)";
  if (tokenState === "wrong") return "the token is wrong; enter the right one above";
  if (tokenState === "none") return "commands need the token; enter it above";
  if (tokenState !== "accepted") return "checking the token…";
  return "";
}

/// Why this hand takes no commands now, or "" when it does.
function blockReason(s) {
  const token = tokenBlock();
  if (token) return token;
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

function setText(element, text) {
  if (element.textContent !== text) element.textContent = text;
}

function nsTimeOfDay(ns) { return ns ? timeOfDay(Math.round(Number(ns) / 1e6)) : "never"; }

// ---- Health: per service what its info says (host, version, admin, buses and
// their links), the domain from dh3-web, what the hands' statuses say per bus.

function serviceCard(name) {
  const found = document.querySelector('article.service[data-service="' + CSS.escape(name) + '"]');
  if (found) return found;
  const card = document.getElementById("service-card").content.firstElementChild.cloneNode(true);
  card.dataset.service = name;
  const list = document.getElementById("services");
  const after = [...list.children].find((other) => other.dataset.service > name);
  list.insertBefore(card, after || null);
  document.getElementById("no-services").hidden = true;
  return card;
}

/// "bus0 (sim:1,2,3): link up; 3 of 4 hands online; hand 4 reports TIMEOUT"
function busInWords(service, bus) {
  const statuses = [...hands.values()].map((entry) => entry.status)
      .filter((s) => s && s.service === service && s.bus === bus.name);
  const online = statuses.filter((s) => s.online && !s.service_lost).length;
  const errors = statuses.filter((s) => s.last_error !== "OK")
      .map((s) => "hand " + s.can_id + " reports " + s.last_error);
  return bus.name + " (" + bus.spec + "): link " + (bus.link_up ? "up" : "DOWN") + "; " + online + " of " +
         bus.hands.length + " hands online" + (errors.length ? "; " + errors.join(", ") : "");
}

function showServiceHealth(info) {
  const card = serviceCard(info.service);
  setText(field(card, "service"), info.service);
  setText(field(card, "state"), info.ready ? "ready" : "LOST: the service left the domain; last known values");
  card.classList.toggle("not-live", !info.ready);
  setText(field(card, "host"), info.host || "?");
  setText(field(card, "version"), info.version || "?");
  setText(field(card, "domain"), consoleHealth ? String(consoleHealth.domain) : "?");
  setText(field(card, "admin"), info.admin_allowed ? "allowed" : "not allowed (its allow_admin is off)");
  setText(field(card, "started"), nsTimeOfDay(info.started_ns));
  const list = field(card, "buses");
  const lines = info.buses.map((bus) => busInWords(info.service, bus));
  if ([...list.children].map((item) => item.textContent).join("\n") !== lines.join("\n")) {
    list.replaceChildren(...info.buses.map((bus, i) => {
      const item = document.createElement("li");
      item.textContent = lines[i];
      item.className = bus.link_up ? "" : "error";
      return item;
    }));
  }
}

function showConsoleHealth() {
  const h = consoleHealth;
  const text = h === null ? "dh3-web's health: " + healthError
      : "dh3-web " + (h.console || "") + " on DDS domain " + h.domain + ": " +
        (h.connected ? "connected" : "NOT connected to the domain") +
        ", services ready: " + h.services_ready + ", hands seen: " + h.hands + "; commands " +
        (h.commands_enabled ? (h.read_only ? "refused (a read-only identity)" : "taken with the token")
                            : "off (started without --token-file)");
  setText(document.getElementById("console-health"), text);
}

function showService(info) {
  services.set(info.service, info);
  showServiceHealth(info);
  showCommissioning();
}

function refresh() {
  showConnection();
  hands.forEach((entry) => { if (entry.status) showLiveness(entry); });
  services.forEach(showServiceHealth);
  showAlarms();
  showCommissioning();
}

const NOT_READ = "position not read yet (the next status says it)";
/// Log lines of motions whose end position was not read yet as the event went
/// out, by hand: the next status read after the event says it.
const awaitingStop = new Map();

/// "at position 30" or, before the service read it, why there is no position.
function where(position) { return position === null ? NOT_READ : "at position " + position; }

function awaitStop(e, item) {
  // A newer motion ends the wait of an older one: the next read is the newer one's.
  if (e.position === null && ["ARRIVED", "GRASPED", "MISSED"].includes(e.kind)) {
    awaitingStop.set(e.hand, {item, timestamp_ns: e.timestamp_ns});
  } else if (["ARRIVED", "GRASPED", "MISSED", "DROPPED"].includes(e.kind)) {
    awaitingStop.delete(e.hand);
  }
}

function showStop(s) {
  const waiting = awaitingStop.get(s.hand);
  if (!waiting || s.position === null || s.grip === "MOVING" || s.read_at_ns < waiting.timestamp_ns) return;
  awaitingStop.delete(s.hand);
  waiting.item.textContent = waiting.item.textContent.replace(NOT_READ, "at position " + s.position +
                                                              " (read just after)");
}

/// An event in the words of the cards: the grip and rotation states, where the
/// motion stopped, the state of the hand as its card shows it.
function eventInWords(e) {
  switch (e.kind) {
    case "ONLINE": return "ONLINE: the hand answers";
    case "OFFLINE":
      return e.from_client ? "LOST: service " + e.hand.split("/")[0] + " lost (seen by dh3-web)"
          : "OFFLINE: the hand does not answer (" + e.value + " requests unanswered)";
    case "INITIALIZED": return "INITIALIZED";
    case "INIT_FAILED": return "Error: initialization failed";
    case "ARRIVED": return "ARRIVED " + where(e.position) + " (target " + numberOrDash(e.target) + ")";
    case "GRASPED": return "GRASPED " + where(e.position) + " with force " + e.value;
    case "MISSED": return "MISSED: closed " + where(e.position) + " without an object (target " +
                          numberOrDash(e.target) + ")";
    case "DROPPED": return "DROPPED: the object fell from the fingers " + where(e.position);
    case "ROTATION_ARRIVED": return "rotation ARRIVED at " + numberOrDash(e.position) + " (target " +
                                    numberOrDash(e.target) + ")";
    case "ROTATION_BLOCKED": return "rotation BLOCKED at " + numberOrDash(e.position) + " (target " +
                                    numberOrDash(e.target) + ")";
    case "FAULT": return "Error: fault";
    default: return e.kind;
  }
}

function showEvent(e) {
  const log = document.getElementById("log");
  const item = document.createElement("li");
  item.className = e.kind.toLowerCase();
  item.dataset.hand = e.hand;
  const when = e.timestamp_ns ? nsToMs(e.timestamp_ns) : Date.now();
  let words = e.hand + (e.name ? " (" + e.name + ")" : "") + " " + eventInWords(e);
  if (e.message) words += ": " + e.message;
  item.textContent = timeOfDay(when) + " " + words;
  log.insertBefore(item, log.firstChild);
  while (log.children.length > LOG_LIMIT) log.removeChild(log.lastChild);
  awaitStop(e, item);
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
  if (httpStatus === 0) return {text: "Error in " + command + ": " + reply.message, error: true};
  return {text: "Error in " + command + " (HTTP " + httpStatus + " " + reply.code + "): " + reply.message,
          error: true};
}

/// POSTs a command: its reply and HTTP status (0 and a reply in words when
/// dh3-web did not answer).
async function post(address, command, body) {
  try {
    const path = "/api/hands/" + address.split("/").map(encodeURIComponent).join("/") + "/" + command;
    const response = await fetch(path, {
      method: "POST",
      headers: headers({"Content-Type": "application/json"}),
      body: JSON.stringify(body),
    });
    if (response.status === 401 && token) setTokenState("wrong");
    return {reply: await response.json(), status: response.status};
  } catch (err) {
    return {reply: {ok: false, message: "no answer from dh3-web (" + err.message + ")"}, status: 0};
  }
}

/// POSTs a command; the reply in words.
async function send(address, command, body) {
  const {reply, status} = await post(address, command, body);
  return describeReply(command, reply, status);
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

// ---- Alarms: dh3-web's list, one for every screen of this console (a hand
// offline, a bus down, a service lost, an object dropped, a command failed):
// acknowledged on one screen, gone from all; a reload forgets nothing. The
// page shows what is not acknowledged yet, and sends the acknowledgement.

let alarmList = {version: -1, alarms: []};

function showAlarmList(list) {
  if (list.version < alarmList.version) return;  // two lists passed each other
  alarmList = list;
  showAlarms();
}

async function loadAlarms() {
  try {
    const response = await fetch("/api/alarms", {headers: headers()});
    if (response.ok) showAlarmList(await response.json());
  } catch (err) {
    // The stream brings the list again; the connection line says dh3-web is away.
  }
}

/// The alarm `item` shows now (an alarm raised again is the same item).
async function acknowledge(item) {
  let problem = "";
  try {
    const response = await fetch("/api/alarms/" + item.dataset.alarmId + "/acknowledge", {method: "POST", headers: headers()});
    if (response.status === 401 && token) setTokenState("wrong");
    if (!response.ok) problem = (await response.json()).message;
  } catch (err) {
    problem = "no answer from dh3-web (" + err.message + ")";
  }
  setText(item.querySelector(".error"), problem ? "Error: not acknowledged: " + problem : "");
  loadAlarms();
}

/// Updates the list in place: an item, and the button under the operator's
/// finger, stays the same element while its alarm lasts.
function showAlarms() {
  const shown = alarmList.alarms.filter((alarm) => !alarm.acknowledged);
  const byKey = new Map(shown.map((alarm) => [alarm.key, alarm]));
  const list = document.getElementById("alarms");
  const items = new Map([...list.children].map((item) => [item.dataset.alarm, item]));
  items.forEach((item, key) => { if (!byKey.has(key)) item.remove(); });
  const blocked = tokenBlock();
  shown.sort((a, b) => b.since_ns - a.since_ns).forEach((alarm, i) => {
    let item = items.get(alarm.key);
    if (!item) {
      item = document.createElement("li");
      item.dataset.alarm = alarm.key;
      const button = document.createElement("button");
      button.type = "button";
      button.textContent = "Acknowledge";
      button.addEventListener("click", () => acknowledge(item));
      const error = document.createElement("span");
      error.className = "error";
      item.append(document.createElement("span"), " ", button, " ", error);
    }
    item.dataset.alarmId = alarm.id;
    item.className = alarm.active ? "active" : "over";
    setText(item.firstChild, nsTimeOfDay(alarm.since_ns) + " " + alarm.text +
            (alarm.active ? "" : " (over since " + nsTimeOfDay(alarm.over_ns) + ")"));
    const button = item.querySelector("button");
    button.disabled = blocked !== "";
    if (blocked) button.title = blocked; else button.removeAttribute("title");
    if (list.children[i] !== item) list.insertBefore(item, list.children[i] || null);
  });
  document.getElementById("no-alarms").hidden = shown.length > 0;
  const active = shown.filter((alarm) => alarm.active).length;
  const summary = document.getElementById("alarm-summary");
  summary.textContent = shown.length === 0 ? "No alarms"
      : "ALARMS: " + active + " active" + (shown.length > active ? ", " + (shown.length - active) + " over" : "");
  summary.className = active ? "error" : "";
}

function handName(s) { return "hand " + s.hand + (s.name ? " (" + s.name + ")" : ""); }

// ---- Commissioning: scan a bus, firmware, a register, forces; CAN ID and
// baud rate (administrative: the service must allow them, and they are
// confirmed in a dialog that says the hand must then be rebooted).

const BUS_WIDE = ["scan", "versions"];

function commissionSection() { return document.getElementById("commission-title").parentElement; }

function selectedStatus() {
  const entry = hands.get(document.getElementById("commission-hand").value);
  return entry ? entry.status : null;
}

function commissionBlock(command, s) {
  if (!s) return "no hand seen yet";
  const token = tokenBlock();
  if (token) return token;
  if (serviceLost(s)) return "its service is lost";
  if (BUS_WIDE.includes(command)) return "";
  const hand = blockReason(s);
  if (hand) return hand;
  const info = services.get(s.service);
  if (command.startsWith("set-") && !(info && info.admin_allowed)) {
    return "admin only: service " + s.service + " does not allow CAN ID and baud-rate changes (allow_admin)";
  }
  return "";
}

function showCommissioning() {
  const select = document.getElementById("commission-hand");
  const addresses = [...hands.keys()].sort();
  if ([...select.options].map((o) => o.value).join() !== addresses.join()) {
    const chosen = select.value;
    select.replaceChildren(...addresses.map((a) => {
      const s = hands.get(a).status;
      return new Option(a + (s && s.name ? " (" + s.name + ")" : ""), a);
    }));
    if (addresses.includes(chosen)) select.value = chosen;
  }
  const s = selectedStatus();
  commissionSection().querySelectorAll("button[data-commission]").forEach((button) => {
    const reason = commissionBlock(button.dataset.commission, s);
    button.disabled = reason !== "";
    if (reason) button.title = reason; else button.removeAttribute("title");
  });
  const bus = commissionBlock("scan", s);
  const hand = commissionBlock("read", s);
  const admin = commissionBlock("set-can-id", s);
  setText(document.getElementById("commission-blocked"), bus ? "Commands off: " + bus
      : (hand ? "Register, forces, CAN ID and baud rate off: " + hand : ""));
  setText(document.getElementById("admin-blocked"),
          admin && admin !== hand ? "CAN ID and baud rate off: " + admin : "");
}

function showCommissionResult(address, command, described) {
  const item = document.createElement("li");
  item.dataset.command = command;
  item.textContent = timeOfDay(Date.now()) + " " + address + " " + described.text;
  item.className = described.error ? "error" : "";
  const list = document.getElementById("commission-results");
  list.insertBefore(item, list.firstChild);
  while (list.children.length > LOG_LIMIT) list.removeChild(list.lastChild);
}

/// The dialog for an administrative command; true if the operator confirmed.
function confirmed(text) {
  const dialog = document.getElementById("confirm");
  document.getElementById("confirm-text").textContent = text;
  dialog.returnValue = "";
  dialog.showModal();
  return new Promise((resolve) => dialog.addEventListener(
      "close", () => resolve(dialog.returnValue === "confirm"), {once: true}));
}

async function scanBus(s) {
  const {reply, status} = await post(s.hand, "scan", {});
  if (!reply.ok) return describeReply("scan", reply, status);
  const info = services.get(s.service);
  const bus = info && info.buses.find((b) => b.name === s.bus);
  const found = reply.found_ids;
  const silent = bus ? bus.hands.map((h) => h.can_id).filter((id) => !found.includes(id)) : [];
  return {text: "scan of bus " + s.service + "/" + s.bus + ": " + (found.length
      ? "hands " + found.join(", ") + " answered" : "no hand answered") +
      (silent.length ? "; configured but silent: " + silent.join(", ") : ""), error: false};
}

async function readVersions(s) {
  const addresses = [...hands.values()].map((entry) => entry.status)
      .filter((o) => o && o.service === s.service && o.bus === s.bus).map((o) => o.hand).sort();
  const replies = await Promise.all(addresses.map((address) => post(address, "version", {})));
  return {text: "firmware: " + replies.map(({reply, status}, i) => "hand " + addresses[i].split("/")[2] + " " +
      (reply.ok ? reply.firmware_version_text + " (raw " + reply.value + ")"
                : describeReply("version", reply, status).text)).join("; "),
          error: replies.some(({reply}) => !reply.ok)};
}

/// The body of a commissioning command from its fields, or null (the reason is
/// beside the field that is not valid).
function commissionBody(command) {
  const section = commissionSection();
  if (command === "read") {
    const register = document.getElementById("register").value.trim();
    setText(document.getElementById("register-error"),
            register ? "" : "Error: empty (a name such as position, or 0xNNNN); nothing sent");
    return register ? {register} : null;
  }
  if (command === "force") {
    const closing = checkField(section, "closing");
    const opening = checkField(section, "opening");
    return closing === null || opening === null ? null : {closing, opening};
  }
  if (command === "set-can-id") {
    const id = checkField(section, "can_id");
    return id === null ? null : {can_id: id, confirm: true};
  }
  if (command === "set-baud") return {index: Number(document.getElementById("baud").value), confirm: true};
  return {};
}

function adminQuestion(command, s, body) {
  if (command === "set-can-id") {
    return "Change the CAN ID of " + handName(s) + " from " + s.can_id + " to " + body.can_id + "?";
  }
  const baud = document.getElementById("baud");
  return "Change the CAN baud rate of " + handName(s) + " to " + baud.options[baud.selectedIndex].text +
         " (index " + body.index + ")?";
}

async function commission(button) {
  const command = button.dataset.commission;
  const s = selectedStatus();
  if (!s) return;
  const body = commissionBody(command);
  if (body === null) {
    showCommissionResult(s.hand, command, {text: command + ": not sent (a field is not valid)", error: false});
    return;
  }
  if (body.confirm && !(await confirmed(adminQuestion(command, s, body)))) {
    showCommissionResult(s.hand, command, {text: command + ": not sent (cancelled)", error: false});
    return;
  }
  button.setAttribute("aria-busy", "true");
  let described;
  if (command === "scan") described = await scanBus(s);
  else if (command === "versions") described = await readVersions(s);
  else {
    const {reply, status} = await post(s.hand, command, body);
    described = describeReply(command, reply, status);
    if (reply.ok && command === "read") described.text = "read " + body.register + ": value " + reply.value;
    if (reply.ok && command.startsWith("set-")) described.text += ": reboot the hand now";
  }
  button.removeAttribute("aria-busy");
  showCommissionResult(s.hand, command, described);
}

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

/// dh3-web's own health (its domain, its name as a lease holder), again every
/// HEALTH_MS.
async function loadHealth() {
  try {
    const response = await fetch("/api/health", {headers: headers()});
    const reply = await response.json();
    consoleHealth = response.ok ? reply : null;
    if (response.ok) consoleName = reply.console || consoleName;
    else healthError = "HTTP " + response.status + ": " + reply.message;
  } catch (err) {
    consoleHealth = null;
    healthError = "no answer from dh3-web (" + err.message + ")";
  }
  showConsoleHealth();
}

document.getElementById("token-form").addEventListener("submit", (event) => {
  event.preventDefault();
  token = document.getElementById("token").value.trim();
  document.getElementById("token").value = "";
  if (token) sessionStorage.setItem("dh3-token", token);
  else sessionStorage.removeItem("dh3-token");
  checkToken();
  loadHealth();
  streamForever();
});
document.getElementById("stop-all").addEventListener("click", stopAll);
commissionSection().querySelectorAll("button[data-commission]").forEach((button) => {
  button.addEventListener("click", () => commission(button));
});
commissionSection().querySelectorAll("input[data-input]").forEach((input) => {
  input.addEventListener("input", () => checkField(commissionSection(), input.dataset.input));
});
document.getElementById("commission-hand").addEventListener("change", showCommissioning);

setInterval(refresh, 500);
setInterval(loadHealth, HEALTH_MS);
loadHealth();
checkToken();
streamForever();
