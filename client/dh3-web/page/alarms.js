// Alarms: dh3-web's list, one for every screen of this console (a hand
// offline, a bus down, a service lost, an object dropped, a command failed):
// acknowledged on one screen, gone from all; a reload forgets nothing. The
// page shows what is not acknowledged yet, and sends the acknowledgement.

"use strict";

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
    offFor([item.querySelector("button")], blocked);
    if (list.children[i] !== item) list.insertBefore(item, list.children[i] || null);
  });
  document.getElementById("no-alarms").hidden = shown.length > 0;
  const active = shown.filter((alarm) => alarm.active).length;
  const summary = document.getElementById("alarm-summary");
  summary.textContent = shown.length === 0 ? "No alarms"
      : "ALARMS: " + active + " active" + (shown.length > active ? ", " + (shown.length - active) + " over" : "");
  summary.className = active ? "error" : "";
}
