// Typesets the math of every page with KaTeX 0.19.1 (MIT), vendored in docs/assets/katex/:
// katex.min.js, katex.min.css, contrib/auto-render.min.js and the woff2 fonts of the npm
// package's dist/, unchanged. No CDN: the site works offline. pymdownx.arithmatex (generic
// mode) writes $...$ as \(...\) and $$...$$ as \[...\] in elements of class "arithmatex";
// only those are rendered.
document$.subscribe(({ body }) => {
  body.querySelectorAll(".arithmatex").forEach((element) => {
    renderMathInElement(element, {
      delimiters: [
        { left: "\\(", right: "\\)", display: false },
        { left: "\\[", right: "\\]", display: true },
      ],
      throwOnError: false,
    });
  });
});
