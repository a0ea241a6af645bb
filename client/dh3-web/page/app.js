// The page's start: what is shown again every half second, the controls'
// handlers, then the health, the token and the stream.
"use strict";

function refresh() {
  showConnection();
  showStopAll();
  hands.forEach((entry) => { if (entry.status) showLiveness(entry); });
  services.forEach(showServiceHealth);
  showAlarms();
  showCommissioning();
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
