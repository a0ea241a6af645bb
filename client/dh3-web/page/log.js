// The event log, in the words of the cards, with where motions stopped.
"use strict";

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

