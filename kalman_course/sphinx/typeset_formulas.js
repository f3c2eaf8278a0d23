// Compose des formules TeX en CHTML (MathJax 3 dans node, adaptateur liteDOM, MathML d'assistance), pour
// kalman_course/sphinx/formulas.py. Entrée (JSON sur stdin) :
//   {mathjax: dossier es5 du paquet npm « mathjax », load: composants, tex: réglages TeX, fontURL: polices,
//    formulas: [[tex, display], …]}
// Sortie (JSON sur stdout) : {html: [conteneur mjx-container, …], errors: [[rang, message], …],
//   css: feuille de style CHTML de toutes les polices (adaptiveCSS: false : la même pour toutes les pages)}.
"use strict";
const fs = require("fs");

const request = JSON.parse(fs.readFileSync(0, "utf8"));
require(request.mathjax + "/node-main.js").init({
  loader: {paths: {mathjax: request.mathjax}, load: ["adaptors/liteDOM", ...request.load], require: require},
  tex: request.tex,
  chtml: {fontURL: request.fontURL, adaptiveCSS: false},
  startup: {typeset: false},
}).then(async (MathJax) => {
  const adaptor = MathJax.startup.adaptor;
  const html = [], errors = [];
  for (const [k, [tex, display]] of request.formulas.entries()) {
    const node = await MathJax.tex2chtmlPromise(tex, {display: display});
    const markup = adaptor.outerHTML(node);
    const error = adaptor.tags(node, "mjx-merror")[0];
    // commande inconnue : l'extension noundefined l'écrit en rouge au lieu d'une erreur
    const unknown = /<mtext mathcolor="red">(\\[^<]*)<\/mtext>/.exec(markup);
    if (error) errors.push([k, adaptor.getAttribute(error, "data-mjx-error") || adaptor.textContent(error)]);
    else if (unknown) errors.push([k, "commande inconnue " + unknown[1]]);
    html.push(markup);
  }
  const css = adaptor.textContent(MathJax.chtmlStylesheet());
  process.stdout.write(JSON.stringify({html: html, errors: errors, css: css}));
}).catch((e) => {
  console.error("MathJax : " + (e && e.stack ? e.stack : e));
  process.exit(1);
});
