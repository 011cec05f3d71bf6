MathJax.Hub.Config({
  TeX: {equationNumbers: {autoNumber: "AMS", useLabelIds: true}},
  tex2jax: {
    inlineMath: [["$", "$"], ["\\(", "\\)"]],
    displayMath: [["$$", "$$"], ["\\[", "\\]"]],
    processEscapes: true,
    processEnvironments: true
  },
  "HTML-CSS": {
    availableFonts: [], preferredFont: null, webFont: "STIX-Web", imageFont: null,
    linebreaks: {automatic: true}
  },
  MMLorHTML: {prefer: {Firefox: "MML", other: "HTML"}},
  menuSettings: {assistiveMML: true},
  showMathMenu: false,
  displayAlign: "center",
  messageStyle: "none"
});
