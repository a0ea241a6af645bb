// The hands' cards: a status shown, whether its values are live, why a hand
// takes no commands, and the connection line above them.
"use strict";

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

/// Why the accepted token's role may not give commands of `level`
/// ("operator": drive the hands; "admin": also change CAN IDs and baud
/// rates), or "" when it may or no token is accepted. dh3-web refuses them
/// all the same; the page says so before anything is clicked.
function roleBlock(level) {
  if (tokenState !== "accepted") return "";
  if (tokenRole !== "operator" && tokenRole !== "admin") {
    return "this token may only view: commands need an operator's token";
  }
  if (level === "admin" && tokenRole !== "admin") {
    return "admin only: this token is an operator's; CAN ID and baud-rate changes need an admin's";
  }
  return "";
}

/// Why no command of `level` (roleBlock's; "operator" unless given) leaves
/// this console now, or "" when they do.
function tokenBlock(level) {
  if (tokenState === "disabled") return "this dh3-web takes no commands (started without --token-file)";
  if (tokenState === "wrong") return "the token is wrong; enter the right one above";
  if (tokenState === "none") return "commands need the token; enter it above";
  if (tokenState !== "accepted") return "checking the token…";
  return roleBlock(level || "operator");
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
  offFor(c.querySelectorAll("button[data-command]"), reason);
  // The fields stay on for a hand that is offline or leased for now, not for
  // a token that may never send what they hold.
  offFor(c.querySelectorAll("input[data-input]"), roleBlock("operator"));
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
