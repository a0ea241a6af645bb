// Health: per service what its info says (host, version, admin, buses and
// their links), the domain from dh3-web, what the hands' statuses say per
// bus; and dh3-web's own health from /api/health.
"use strict";

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
