// The marking page (labkit mark): DATA is put in by labkit.grading.reports.marking.write_page.
(function(){
"use strict";
var DATA = __DATA__;
var KEY = "labkit-marks:" + DATA.run;
var order = [];
DATA.tasks.forEach(function(t, i){ t.answers.forEach(function(a, j){ order.push([i, j]); }); });
var state = {pos: 0, marks: {}};
try { var saved = JSON.parse(localStorage.getItem(KEY) || "null"); if (saved) state = saved; } catch (e) {}
function save(){ try { localStorage.setItem(KEY, JSON.stringify(state)); } catch (e) {} }
function id(t, a){ return JSON.stringify([a.submission, t.item]); }
function $(x){ return document.getElementById(x); }
function current(){ var p = order[state.pos]; return p ? [DATA.tasks[p[0]], DATA.tasks[p[0]].answers[p[1]]] : null; }
function text(points, kind){ if (kind === "held") return points === 1 ? "release" : "keep"; return String(points); }
function show(){
  var left = order.filter(function(p){ var t = DATA.tasks[p[0]]; return !state.marks[id(t, t.answers[p[1]])]; }).length;
  $("progress").textContent = left + " of " + order.length + " left to mark";
  var c = current(); if (!c) { $("title").textContent = "Nothing to mark"; return; }
  var t = c[0], a = c[1], m = state.marks[id(t, a)];
  $("title").textContent = t.title + " (" + (state.pos + 1) + " of " + order.length + ")";
  $("question").innerHTML = t.question; $("model").innerHTML = t.model || "<p>(none)</p>";
  $("worth").textContent = t.kind === "held" ? "" : "(worth " + t.max + ")";
  $("who").textContent = a.shown; $("answer").innerHTML = a.html;
  $("given").textContent = m ? "Marked: " + text(m.points, t.kind) : "Not marked yet";
  $("comment").value = m ? m.comment : "";
  var seen = {}, list = $("comments"); list.textContent = "";
  Object.keys(state.marks).forEach(function(k){ var s = state.marks[k].comment;
    if (s && !seen[s]) { seen[s] = 1; var o = document.createElement("option"); o.value = s; list.appendChild(o); } });
}
function give(points){
  var c = current(); if (!c) return; var t = c[0], a = c[1];
  if (points > t.max) return;
  state.marks[id(t, a)] = {points: points, comment: $("comment").value, submission: a.submission,
    item: t.item, kind: t.kind};
  save(); show();
}
function move(by){ state.pos = Math.max(0, Math.min(order.length - 1, state.pos + by)); save(); show(); }
$("comment").addEventListener("input", function(){
  var c = current(); if (!c) return; var m = state.marks[id(c[0], c[1])]; if (m) { m.comment = this.value; save(); } });
$("comment").addEventListener("keydown", function(e){
  if (e.key === "Escape" || e.key === "Enter") { this.blur(); e.preventDefault(); } });
document.addEventListener("keydown", function(e){
  if (e.target === $("comment") || e.ctrlKey || e.metaKey || e.altKey) return;
  if (/^[0-9]$/.test(e.key)) { give(Number(e.key)); e.preventDefault(); }
  else if (e.key === "j" || e.key === "ArrowRight") { move(1); e.preventDefault(); }
  else if (e.key === "k" || e.key === "ArrowLeft") { move(-1); e.preventDefault(); }
  else if (e.key === "c") { $("comment").focus(); e.preventDefault(); }
});
function cell(s){ s = String(s); if (/^[=+\-@\t\r]/.test(s)) s = "'" + s;
  return /[",\n\r]/.test(s) ? '"' + s.replace(/"/g, '""') + '"' : s; }
$("download").addEventListener("click", function(){
  var rows = ["submission,item,points,comment"];
  Object.keys(state.marks).forEach(function(k){ var m = state.marks[k];
    rows.push([cell(m.submission), cell(m.item), text(m.points, m.kind), cell(m.comment || "")].join(",")); });
  var blob = new Blob([rows.join("\r\n") + "\r\n"], {type: "text/csv"});
  var link = document.createElement("a"); link.href = URL.createObjectURL(blob); link.download = "marks.csv";
  document.body.appendChild(link); link.click(); link.remove();
});
show();
})();
