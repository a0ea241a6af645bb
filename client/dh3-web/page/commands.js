// Commands from the cards: values checked before anything is sent, POST
// /api/hands/SERVICE/BUS/ID/COMMAND, the reply in words, Stop all; and the
// token, checked as soon as it is set.
"use strict";

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

/// Why STOP ALL is off: only when dh3-web is known to refuse this console's
/// stops (no token, a wrong one, a viewer's, no commands at all); while the
/// token is being checked, or could not be, it stays on and dh3-web decides.
function stopAllBlock() {
  return tokenState === "checking" || tokenState === "unknown" ? "" : tokenBlock();
}

function showStopAll() {
  const reason = stopAllBlock();
  offFor([document.getElementById("stop-all")], reason);
  const blocked = document.getElementById("stop-all-blocked");
  setText(blocked, reason ? "Stop all off: " + reason : "");
  blocked.hidden = !reason;
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

/// What an accepted token's role lets its holder do, in words.
const ROLE_WORDS = {
  view: "Token accepted: view. This token may only view: every command is off.",
  operator: "Token accepted: operator. Commands go to the hands; CAN ID and baud-rate changes are " +
            "admin only.",
  admin: "Token accepted: admin. Commands go to the hands, CAN ID and baud-rate changes too.",
};

function setTokenState(state, detail, role) {
  tokenState = state;
  tokenRole = state === "accepted" ? role : "";
  const words = {
    none: "No token: the hands can be watched, not driven.",
    checking: "Checking the token…",
    accepted: ROLE_WORDS[tokenRole] || ROLE_WORDS.view,
    wrong: "Error: the token is wrong (dh3-web refused it); commands are off.",
    disabled: "Error: this dh3-web takes no commands (started without --token-file).",
    unknown: "Error: the token could not be checked (" + (detail || "no answer") + "); commands are off.",
  };
  const shown = document.getElementById("token-state");
  shown.textContent = words[state];
  shown.className = state === "accepted" ? (roleBlock("operator") ? "" : "ok")
      : (state === "none" || state === "checking" ? "" : "error");
  shown.dataset.role = tokenRole;
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
      setTokenState("accepted", "", reply.role);
    } else {
      setTokenState(response.status === 403 ? "disabled" : (response.status === 401 ? "wrong" : "unknown"),
                    reply.message);
    }
  } catch (err) {
    setTokenState("unknown", err.message);
  }
}
