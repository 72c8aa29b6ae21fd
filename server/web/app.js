// contactd's web page: the token field, the job list (polled), the submit form (paste a job or pick an example)
// and the selected job (job_view.js). The selection is in the address (#job=<id>), so a job's page can be
// bookmarked and shared (the token is not in it).

import {ApiError, api, errorFrom, getToken, headers, setToken} from "./api.js";
import {JobView} from "./job_view.js";

const $ = (id) => document.getElementById(id);
const LIST_PERIOD_MS = 2000;

let listTimer = null;
// The ETag of the list drawn: sent back, the server answers 304 while no job was added, removed or changed state.
// It is weak: it does not follow a running job's iterations, so while a listed job runs the list is asked for whole.
let listTag = "";
const view = new JobView({onChange: () => refreshList()});

function banner(text) {
  const el = $("banner");
  el.textContent = text || "";
  el.hidden = !text;
}

function submitMessage(lines, error) {
  const el = $("submit-message");
  el.textContent = Array.isArray(lines) ? lines.join("\n") : lines;
  el.className = "message" + (error ? " error" : " ok");
}

function age(iso) {
  const t = Date.parse(iso);
  if (!isFinite(t)) return "";
  const s = Math.max(0, (Date.now() - t) / 1000);
  if (s < 60) return `${Math.round(s)} s ago`;
  if (s < 3600) return `${Math.round(s / 60)} min ago`;
  if (s < 86400) return `${Math.round(s / 3600)} h ago`;
  return new Date(t).toISOString().slice(0, 10);
}

function selectedId() {
  const m = /^#job=([0-9a-f-]{36})$/.exec(window.location.hash);
  return m ? m[1] : null;
}

function select(id) {
  if (id) {
    if (window.location.hash !== `#job=${id}`) window.location.hash = `job=${id}`;
    view.show(id);
  }
  for (const tr of $("jobs").children) tr.classList.toggle("selected", tr.dataset.id === id);
}

async function refreshList() {
  clearTimeout(listTimer);
  try {
    const running = [...$("jobs").children].some((tr) => tr.dataset.state === "RUNNING");
    const conditional = listTag && !running;
    const response = await fetch("v1/jobs?page_size=50", {
      headers: headers(conditional ? {"Accept": "application/json", "If-None-Match": listTag} : {"Accept": "application/json"}),
      cache: "no-store"});
    if (response.status === 304) {
      banner("");
      for (const tr of $("jobs").children) {
        tr.classList.toggle("selected", tr.dataset.id === view.id);
        if (tr.lastElementChild) tr.lastElementChild.textContent = age(tr.dataset.created);
      }
      if (!document.hidden) listTimer = setTimeout(refreshList, LIST_PERIOD_MS);
      return;
    }
    if (!response.ok) throw await errorFrom(response);
    const page = await response.json();
    listTag = response.headers.get("ETag") || "";
    banner("");
    const rows = (Array.isArray(page.jobs) ? page.jobs : []).map((j) => {
      const tr = document.createElement("tr");
      tr.dataset.id = j.id;
      tr.dataset.state = j.state;
      tr.dataset.created = j.created || "";
      tr.title = j.id;
      const cells = [j.name, j.state, j.iterations, age(j.created)];
      cells.forEach((v, i) => {
        const td = document.createElement("td");
        td.textContent = v === undefined || v === null ? "" : String(v);
        if (i === 1) td.className = "state state-" + j.state;
        tr.append(td);
      });
      tr.addEventListener("click", () => select(j.id));
      tr.classList.toggle("selected", j.id === view.id);
      return tr;
    });
    $("jobs").replaceChildren(...rows);
    $("jobs-status").textContent = rows.length ? (page.next_page_token ? "the newest 50 jobs" : "") : "no jobs yet";
  } catch (e) {
    if (e instanceof ApiError && e.status === 401) {
      banner(getToken() ? "The server refused the token: check it and press Use."
                        : "This server requires a bearer token: enter it at the top and press Use.");
    } else {
      banner(e instanceof TypeError ? "cannot reach the server (is contactd running?)" : e.message);
    }
    listTag = "";
  }
  if (!document.hidden) listTimer = setTimeout(refreshList, LIST_PERIOD_MS);
}

async function loadExamples() {
  try {
    const list = await api("v1/examples");
    const select = $("example");
    for (const e of list.examples || []) {
      const option = document.createElement("option");
      option.value = e.name;
      option.textContent = e.name;
      select.append(option);
    }
  } catch (e) {
    // The list fails for the same reason as the job list (a token), which the banner already says.
  }
}

async function pickExample() {
  const name = $("example").value;
  if (!name) return;
  try {
    const response = await fetch(`v1/examples/${encodeURIComponent(name)}`, {headers: headers(), cache: "no-store"});
    if (!response.ok) throw new Error(`${response.status}: cannot load the example`);
    $("job-text").value = await response.text();
    submitMessage("", false);
  } catch (e) {
    submitMessage(e.message, true);
  }
}

async function validate() {
  try {
    const r = await api("v1/validate", {method: "POST", body: $("job-text").value});
    const bodies = (r.bodies || []).map((b) => `${b.name} ${b.elements} cells`).join(", ");
    submitMessage(`valid: ${r.dofs} unknowns (${bodies}), ${r.contacts} contact pair(s)`, false);
  } catch (e) {
    submitMessage(e.lines || [String(e)], true);
  }
}

async function submit(ev) {
  ev.preventDefault();
  const text = $("job-text").value;
  if (!text.trim()) {
    submitMessage("paste a job (JSON) or pick an example first", true);
    return;
  }
  $("submit").disabled = true;
  try {
    const job = await api("v1/jobs", {method: "POST", body: text});
    submitMessage(`submitted: ${job.name} (${job.id})`, false);
    select(job.id);
    refreshList();
  } catch (e) {
    submitMessage(e.lines || [String(e)], true);
  } finally {
    $("submit").disabled = false;
  }
}

function useToken(ev) {
  ev.preventDefault();
  setToken($("token").value.trim());
  $("token-state").textContent = getToken() ? "token set" : "no token";
  refreshList();
  if ($("example").childElementCount <= 1) loadExamples();
  const id = view.id;
  if (id) {  // follow the selected job again, now with the token
    view.hide();
    select(id);
  }
}

async function start() {
  $("token").value = getToken();
  $("token-state").textContent = getToken() ? "token set" : "";
  $("token-form").addEventListener("submit", useToken);
  $("example").addEventListener("change", pickExample);
  $("validate").addEventListener("click", validate);
  $("submit-form").addEventListener("submit", submit);
  window.addEventListener("hashchange", () => select(selectedId()));
  document.addEventListener("visibilitychange", () => { if (!document.hidden) refreshList(); });
  fetch("./", {headers: {"Accept": "application/json"}, cache: "no-store"}).then((r) => r.json())
      .then((info) => { $("version").textContent = info.version ? `version ${info.version}` : ""; })
      .catch(() => {});
  loadExamples();
  await refreshList();
  select(selectedId());
}

start();
