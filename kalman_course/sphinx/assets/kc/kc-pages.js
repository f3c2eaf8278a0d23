/* « Filtre de Kalman » : figures à curseurs chargées à la demande, accessibilité des pages.
   Écrit par kalman_course.sphinx.pages ; aucune dépendance, aucune requête hors du site. */
(function () {
  "use strict";
  var script = document.currentScript;
  var bokehUrls = [];
  try { bokehUrls = JSON.parse((script && script.getAttribute("data-bokeh")) || "[]"); } catch (e) { bokehUrls = []; }

  // ------------------------------------------------------------------ chargement à la demande

  function loadScript(src) {
    return new Promise(function (resolve, reject) {
      var s = document.createElement("script");
      s.src = src;
      s.onload = resolve;
      s.onerror = function () { reject(new Error("échec du chargement de " + src)); };
      document.head.appendChild(s);
    });
  }

  var bokehReady = null;
  function loadBokeh() {
    if (window.Bokeh && window.Bokeh.embed && window.Bokeh.Widgets) return Promise.resolve();
    if (!bokehReady) {
      bokehReady = bokehUrls.reduce(function (p, url) {
        return p.then(function () { return loadScript(url); });
      }, Promise.resolve());
    }
    return bokehReady;
  }

  function loadData(id) {
    var el = document.getElementById(id + "-item");
    var src = el.getAttribute("data-src");
    if (!src) return Promise.resolve(JSON.parse(el.textContent));
    return loadScript(src).then(function () { return window.kcFigureData[id]; });
  }

  // Éléments d'une figure, ombres (shadow DOM) de BokehJS comprises.
  function deepAll(root, selector) {
    var out = [];
    (function walk(node) {
      if (!node) return;
      if (node.querySelectorAll) out.push.apply(out, node.querySelectorAll(selector));
      var all = node.querySelectorAll ? node.querySelectorAll("*") : [];
      for (var i = 0; i < all.length; i++) if (all[i].shadowRoot) walk(all[i].shadowRoot);
    })(root);
    return out.filter(function (el, i) { return out.indexOf(el) === i; });
  }

  // Chaque curseur annoncé par son nom français et la valeur affichée (avec unité), pas son indice.
  function announce(id) {
    var meta = document.getElementById(id + "-sliders");
    if (!meta) return;
    var sliders = JSON.parse(meta.textContent);
    window.setTimeout(function () {
      for (var k = 0; k < sliders.length; k++) {
        var box = document.getElementById(id + "-slider-" + k);
        var handle = box && deepAll(box, ".noUi-handle")[0];
        if (!handle) continue;
        var index = Math.round(Number(handle.getAttribute("aria-valuenow")));
        handle.setAttribute("aria-label", sliders[k].name);
        handle.setAttribute("aria-valuetext", sliders[k].values[index] || "");
      }
    }, 0);
  }

  var drawn = {};
  var documents = {};
  function draw(id) {
    if (drawn[id]) return drawn[id];
    var root = document.getElementById(id);
    var rootIds = [];
    drawn[id] = loadBokeh().then(function () { return loadData(id); }).then(function (item) {
      var missing = root.querySelector(".kc-bokeh-missing");
      if (missing) missing.parentNode.removeChild(missing);
      rootIds = item.render_items[0].root_ids;
      return window.Bokeh.embed.embed_items(item.docs_json, item.render_items);
    }).then(function () {
      // le document Bokeh de la figure (les tests et les outils le retrouvent par l'identifiant)
      window.Bokeh.documents.forEach(function (doc) {
        if (doc.get_model_by_id(rootIds[0])) documents[id] = doc;
      });
      // titre « nom : valeur » des curseurs : sur un téléphone, il passe à la ligne (la valeur reste lisible)
      deepAll(root, ".bk-slider-title").forEach(function (t) { t.style.whiteSpace = "normal"; });
      root.setAttribute("data-kc-ready", "1");
      announce(id);
      var handles = [];
      for (var k = 0; document.getElementById(id + "-slider-" + k); k++) {
        handles = handles.concat(deepAll(document.getElementById(id + "-slider-" + k), ".noUi-handle"));
      }
      handles.forEach(function (h) {
        h.addEventListener("keyup", function () { announce(id); });
        h.addEventListener("pointerup", function () { announce(id); });
      });
    });
    return drawn[id];
  }

  var figures = [];
  var observer = "IntersectionObserver" in window ? new IntersectionObserver(function (entries) {
    entries.forEach(function (entry) {
      if (!entry.isIntersecting) return;
      observer.unobserve(entry.target);
      draw(entry.target.getAttribute("data-kc-id"));
    });
  }, {rootMargin: "300px 0px"}) : null;

  function register(id) {
    if (figures.indexOf(id) >= 0) return;
    figures.push(id);
    var figure = document.getElementById(id + "-figure");
    if (observer && figure) {
      figure.setAttribute("data-kc-id", id);
      observer.observe(figure);
    } else {
      draw(id);
    }
  }

  function loadAll() {
    document.querySelectorAll(".kc-bokeh-root").forEach(function (r) { register(r.id); });
    return Promise.all(figures.map(draw));
  }

  window.kcFigures = {register: register, draw: draw, loadAll: loadAll, announce: announce, figures: figures,
                      documents: documents};
  window.addEventListener("beforeprint", loadAll);

  // ------------------------------------------------------------------ la page

  function onReady(fn) {
    if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", fn);
    else fn();
  }

  // Hauteur de l'en-tête collant du thème : les curseurs se collent juste dessous.
  function stickyTop() {
    var top = 0;
    document.querySelectorAll(".bd-header, .bd-header-article, .header-article").forEach(function (el) {
      var style = window.getComputedStyle(el);
      if ((style.position === "sticky" || style.position === "fixed") && style.display !== "none") {
        top = Math.max(top, el.getBoundingClientRect().height);
      }
    });
    document.documentElement.style.setProperty("--kc-sticky-top", Math.round(top) + "px");
  }

  onReady(function () {
    document.querySelectorAll(".kc-bokeh-root").forEach(function (r) { register(r.id); });
    stickyTop();
    window.addEventListener("resize", stickyTop);
    window.addEventListener("load", stickyTop);
    // l'en-tête grandit quand ses polices et ses boutons arrivent : suivre sa hauteur
    if (window.ResizeObserver) {
      var watch = new ResizeObserver(stickyTop);
      document.querySelectorAll(".bd-header, .bd-header-article, .header-article").forEach(function (el) {
        watch.observe(el);
      });
    }

    // Lien d'évitement vers la première figure à curseurs, juste après « aller au contenu » du thème.
    var first = document.querySelector(".kc-bokeh-figure");
    if (first && !document.querySelector(".kc-skip-figure")) {
      var link = document.createElement("a");
      link.className = "skip-link kc-skip-figure";
      link.href = "#" + first.id;
      link.textContent = "Aller à la figure à curseurs";
      link.addEventListener("click", function () {
        draw(first.id.replace(/-figure$/, ""));
        window.setTimeout(function () { first.focus(); }, 0);
      });
      var skip = document.querySelector(".skip-link");
      if (skip && skip.parentNode) skip.parentNode.insertBefore(link, skip.nextSibling);
      else document.body.insertBefore(link, document.body.firstChild);
    }

    // Boutons du thème : le nom accessible contient le texte visible (« Recherche Ctrl+K »).
    document.querySelectorAll(".search-button-field[aria-label]").forEach(function (b) {
      b.removeAttribute("aria-label");
    });

    // Formules à la hauteur d'x du texte (ce que ferait MathJax dans la page : x des polices TeX = 0,442 em).
    var probe = document.createElement("span");
    probe.style.cssText = "position:absolute;visibility:hidden;width:100ex;height:0;font-size:100px";
    document.body.appendChild(probe);
    var ex = probe.getBoundingClientRect().width / 100 / 100;
    document.body.removeChild(probe);
    if (ex > 0.2 && ex < 0.8) document.documentElement.style.setProperty("--kc-math-scale", (ex / 0.442).toFixed(3));

    // Équations hors cadre (petit écran) : défilement horizontal, au clavier aussi.
    var scrollable = function () {
      document.querySelectorAll("mjx-container[display='true']").forEach(function (m) {
        var box = m.closest("div.math") || m.parentElement;
        if (box.scrollWidth > box.clientWidth + 1) {
          box.setAttribute("tabindex", "0");
          if (!box.getAttribute("aria-label")) box.setAttribute("aria-label", "Formule (défilement horizontal)");
          box.setAttribute("role", "region");
        } else if (box.getAttribute("role") === "region") {
          box.removeAttribute("tabindex");
          box.removeAttribute("role");
          box.removeAttribute("aria-label");
        }
      });
    };
    // (formules composées à la construction : kalman_course.sphinx.formulas ; polices chargées à « load »)
    scrollable();
    window.addEventListener("load", scrollable);
    window.addEventListener("resize", scrollable);

    // Recherche : extraits sans TeX brut.
    // (searchtools.js de Sphinx 7 déclare « const Search » : nom global, mais pas propriété de window)
    var search = typeof Search !== "undefined" ? Search : window.Search;  // eslint-disable-line no-undef
    if (search && search.makeSearchSummary && !search.kcReadable) {
      var original = search.makeSearchSummary;
      search.makeSearchSummary = function (htmlText, keywords, anchor) {
        return original.call(this, articleOnly(readableMath(htmlText)), keywords, anchor);
      };
      search.kcReadable = true;
    }
  });

  // ------------------------------------------------------------------ formules en texte (recherche)

  var GREEK = {alpha: "α", beta: "β", gamma: "γ", delta: "δ", epsilon: "ε", varepsilon: "ε", eta: "η",
    theta: "θ", kappa: "κ", lambda: "λ", mu: "μ", nu: "ν", xi: "ξ", pi: "π", rho: "ρ", sigma: "σ", tau: "τ",
    phi: "φ", varphi: "φ", chi: "χ", psi: "ψ", omega: "ω", Gamma: "Γ", Delta: "Δ", Theta: "Θ", Lambda: "Λ",
    Sigma: "Σ", Phi: "Φ", Psi: "Ψ", Omega: "Ω", ell: "ℓ", infty: "∞", approx: "≈", le: "≤", leq: "≤",
    ge: "≥", geq: "≥", neq: "≠", times: "×", cdot: "·", pm: "±", to: "→", rightarrow: "→", in: "∈",
    sum: "Σ", partial: "∂", nabla: "∇", top: "ᵀ", star: "*", mid: "|", quad: " ", qquad: " ", ldots: "…",
    dots: "…", lvert: "|", rvert: "|", lVert: "‖", rVert: "‖"};
  var SUP = {"0": "⁰", "1": "¹", "2": "²", "3": "³", "4": "⁴", "5": "⁵", "6": "⁶", "7": "⁷", "8": "⁸",
    "9": "⁹", "-": "⁻", "+": "⁺", "T": "ᵀ", "n": "ⁿ", "i": "ⁱ", "k": "ᵏ", "*": "*"};
  var SUB = {"0": "₀", "1": "₁", "2": "₂", "3": "₃", "4": "₄", "5": "₅", "6": "₆", "7": "₇", "8": "₈",
    "9": "₉", "-": "₋", "+": "₊", "n": "ₙ", "k": "ₖ", "i": "ᵢ", "j": "ⱼ", "m": "ₘ", "a": "ₐ", "e": "ₑ",
    "o": "ₒ", "x": "ₓ", "r": "ᵣ", "t": "ₜ", "p": "ₚ", "s": "ₛ"};

  function toScript(text, table, mark) {
    text = text.replace(/\s+/g, "");
    var all = true;
    for (var i = 0; i < text.length; i++) if (table[text[i]] === undefined) all = false;
    if (all) return text.split("").map(function (c) { return table[c]; }).join("");
    return text.length > 1 ? mark + "(" + text + ")" : mark + text;
  }

  // Une formule TeX en texte lisible : « \hat x_{n}^- » → « x̂ₙ⁻ ».
  function texToText(tex) {
    var t = tex;
    t = t.replace(/\\(?:hat|widehat)\s*\{([^{}]*)\}|\\(?:hat|widehat)\s*(\\?[A-Za-z])/g,
      function (m, a, b) { return (a || b) + "\u0302"; });
    t = t.replace(/\\(?:bar|overline)\s*\{([^{}]*)\}/g, "$1\u0304");
    t = t.replace(/\\tilde\s*\{([^{}]*)\}|\\tilde\s*([A-Za-z])/g, function (m, a, b) { return (a || b) + "\u0303"; });
    t = t.replace(/\\[dt]?frac\s*\{([^{}]*)\}\s*\{([^{}]*)\}/g, "($1)/($2)");
    t = t.replace(/\\sqrt\s*\{([^{}]*)\}/g, "√($1)");
    t = t.replace(/\\(?:mathrm|mathbf|mathcal|mathbb|text|operatorname|boldsymbol)\s*\{([^{}]*)\}/g, "$1");
    t = t.replace(/\\(?:begin|end)\s*\{[^{}]*\}(?:\{[^{}]*\})?/g, " ");  // environnements (aligned…)
    t = t.replace(/\\(left|right|big|Big|bigl|bigr|Bigl|Bigr)\b/g, "");
    t = t.replace(/\\([A-Za-z]+)/g, function (m, name) { return GREEK[name] !== undefined ? GREEK[name] : ""; });
    t = t.replace(/\^\{([^{}]*)\}|\^(\S)/g, function (m, a, b) { return toScript(a !== undefined ? a : b, SUP, "^"); });
    t = t.replace(/_\{([^{}]*)\}|_(\S)/g, function (m, a, b) { return toScript(a !== undefined ? a : b, SUB, "_"); });
    t = t.replace(/\\[,;:!]/g, " ").replace(/[{}]/g, "").replace(/\\\\/g, " ").replace(/\\/g, "");
    t = t.replace(/&/g, " ");  // colonnes d'alignement
    return t.replace(/\s+/g, " ").trim();
  }
  window.kcTexToText = texToText;

  function decode(text) {  // entités HTML de la page (&lt; …) décodées sans rien exécuter
    var area = document.createElement("textarea");
    area.innerHTML = text;
    return area.value;
  }

  function readableMath(htmlText) {
    // formules composées à la construction : leur TeX est dans data-kc-tex (kalman_course.sphinx.formulas)
    htmlText = htmlText.replace(/<mjx-container[^>]*\sdata-kc-tex="([^"]*)"[^>]*>[\s\S]*?<\/mjx-container>/g,
      function (m, tex) {
        return texToText(decode(tex)).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
      });
    return htmlText.replace(/\\\(([\s\S]*?)\\\)|\\\[([\s\S]*?)\\\]|\$\$([\s\S]*?)\$\$/g, function (m, a, b, c) {
      return texToText(decode(a !== undefined ? a : (b !== undefined ? b : c)));
    });
  }
  window.kcReadableMath = readableMath;

  // L'extrait d'un résultat de recherche ne lit que l'article de la page : ni sa table des matières (barre
  // latérale, menu « Contenu »), ni l'en-tête, ni le bloc « Importations du chapitre », ni les liens
  // « précédent / suivant » (Sphinx lit tout l'élément [role=main]).
  var NOT_CONTENT = [".bd-sidebar-secondary", ".bd-toc", ".bd-header-article", ".header-article",
    "#pst-page-navigation-heading", ".prev-next-area", ".prev-next-footer", ".kc-imports", ".headerlink",
    "nav", "footer", ".kc-bokeh-figure script"];
  function articleOnly(htmlText) {
    var doc = new DOMParser().parseFromString(htmlText, "text/html");
    var article = doc.querySelector("article.bd-article") || doc.querySelector("[role=main]");
    if (!article) return htmlText;
    NOT_CONTENT.forEach(function (sel) {
      article.querySelectorAll(sel).forEach(function (el) { el.parentNode.removeChild(el); });
    });
    return '<div role="main">' + article.innerHTML + "</div>";
  }
  window.kcArticleOnly = articleOnly;
})();
