// dh3 web console: what every part of the page shares: the limits, the
// hands and services as last seen, the token, and small helpers in the
// page's words. The page's scripts are loaded in order by index.html (this
// one first, app.js last, which starts it); no libraries, no build step.
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
/// The accepted token's role as dh3-web names it: "view", "operator" or
/// "admin"; "" while no token is accepted.
let tokenRole = "";
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

function setText(element, text) {
  if (element.textContent !== text) element.textContent = text;
}

function nsTimeOfDay(ns) { return ns ? timeOfDay(Math.round(Number(ns) / 1e6)) : "never"; }

function handName(s) { return "hand " + s.hand + (s.name ? " (" + s.name + ")" : ""); }

/// Disables each of `controls` (buttons, fields, lists) with `reason` as its title,
/// or enables it when `reason` is "".
function offFor(controls, reason) {
  controls.forEach((control) => {
    control.disabled = reason !== "";
    if (reason) control.title = reason; else control.removeAttribute("title");
  });
}
