// Commissioning: scan a bus, firmware, a register, forces; CAN ID and
// baud rate (administrative: the service must allow them, the token must be
// an admin's, and they are confirmed in a dialog that says the hand must
// then be rebooted).

"use strict";

const BUS_WIDE = ["scan", "versions"];
/// The commands dh3-web takes only with an admin's token.
const ADMIN_ONLY = ["set-can-id", "set-baud"];

function commissionSection() { return document.getElementById("commission-title").parentElement; }

function selectedStatus() {
  const entry = hands.get(document.getElementById("commission-hand").value);
  return entry ? entry.status : null;
}

function commissionBlock(command, s) {
  if (!s) return "no hand seen yet";
  const token = tokenBlock(ADMIN_ONLY.includes(command) ? "admin" : "operator");
  if (token) return token;
  if (serviceLost(s)) return "its service is lost";
  if (BUS_WIDE.includes(command)) return "";
  const hand = blockReason(s);
  if (hand) return hand;
  const info = services.get(s.service);
  if (ADMIN_ONLY.includes(command) && !(info && info.admin_allowed)) {
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
    offFor([button], commissionBlock(button.dataset.commission, s));
  });
  // The fields of what this token may never send are off too.
  const section = commissionSection();
  offFor([document.getElementById("register"), ...section.querySelectorAll(
      'input[data-input="closing"], input[data-input="opening"]')], roleBlock("operator"));
  offFor([section.querySelector('input[data-input="can_id"]'), document.getElementById("baud")],
         roleBlock("admin"));
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
