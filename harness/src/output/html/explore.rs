//! The one inline script of every report page: each table with a header becomes sortable by a
//! click on a header (numbers, percentages and `1.2e-3` by value, text by its words, empty and `-`
//! cells last in either direction; a cell of the `num` class by its first number, as in
//! `x2.5 [1.2, 4.8]`; stable; an arrow marks the sorted column), and each table of
//! more than [`FILTER_ROWS`] rows gets a text box above it that hides the rows not containing the
//! text, with a count of the rows shown. Without the script the tables are plain tables.

/// Tables with more rows than this get a filter box.
pub const FILTER_ROWS: usize = 20;

/// The id of the script element (a page carries it once).
pub const SCRIPT_ID: &str = "mcbench-explore";

/// The script's source (`@ROWS@` stands for [`FILTER_ROWS`]).
const SOURCE: &str = r#"(function () {
  var NUM = /^[-+]?(\d[\d,]*\.?\d*|\.\d+)(e[-+]?\d+)?\s*(%|x|\u00d7)?$/i;
  function key(cell) {
    var t = cell ? cell.textContent.trim() : '';
    if (t === '' || t === '-' || t === '\u2013') return null;
    var lead = t.replace(/^[\[x\u00d7]/, '').split(/[\s\u00b1\[,;]/)[0];
    if (NUM.test(t) || (cell.classList.contains('num') && NUM.test(lead))) {
      var n = parseFloat((NUM.test(t) ? t : lead).replace(/,/g, ''));
      if (!isNaN(n)) return n;
    }
    return t.toLowerCase();
  }
  function cmp(a, b) {
    if (typeof a !== typeof b) return typeof a === 'number' ? -1 : 1;
    return a < b ? -1 : a > b ? 1 : 0;
  }
  function sort(table, th, col) {
    var dir = th.getAttribute('aria-sort') === 'ascending' ? -1 : 1;
    [].forEach.call(table.tHead.rows[0].cells, function (h) { h.removeAttribute('aria-sort'); });
    th.setAttribute('aria-sort', dir > 0 ? 'ascending' : 'descending');
    var body = table.tBodies[0];
    var rows = [].map.call(body.rows, function (r, i) { return [key(r.cells[col]), i, r]; });
    rows.sort(function (x, y) {
      if (x[0] === null || y[0] === null) return (x[0] === null) - (y[0] === null) || x[1] - y[1];
      return dir * cmp(x[0], y[0]) || x[1] - y[1];
    });
    rows.forEach(function (x) { body.appendChild(x[2]); });
  }
  function filter(table) {
    var rows = table.tBodies[0].rows, n = rows.length;
    var box = document.createElement('div'), input = document.createElement('input');
    var count = document.createElement('span');
    box.className = 'filter';
    input.type = 'search';
    input.placeholder = 'filter rows';
    input.setAttribute('aria-label', 'filter the rows of the table below');
    count.className = 'muted';
    function update() {
      var q = input.value.trim().toLowerCase(), shown = 0;
      [].forEach.call(rows, function (r) {
        var keep = r.textContent.toLowerCase().indexOf(q) >= 0;
        r.hidden = !keep;
        shown += keep ? 1 : 0;
      });
      count.textContent = shown + ' of ' + n + ' rows';
    }
    input.addEventListener('input', update);
    box.appendChild(input);
    box.appendChild(document.createTextNode(' '));
    box.appendChild(count);
    var at = table.parentNode.classList.contains('scroll') ? table.parentNode : table;
    at.parentNode.insertBefore(box, at);
    update();
  }
  [].forEach.call(document.querySelectorAll('table'), function (table) {
    if (!table.tHead || !table.tBodies.length || !table.tHead.rows.length) return;
    [].forEach.call(table.tHead.rows[0].cells, function (th, col) {
      th.classList.add('sortable');
      th.tabIndex = 0;
      th.title = 'sort by this column (again: reverse)';
      th.addEventListener('click', function () { sort(table, th, col); });
      th.addEventListener('keydown', function (e) { if (e.key === 'Enter') sort(table, th, col); });
    });
    if (table.tBodies[0].rows.length > @ROWS@) filter(table);
  });
})();
"#;

/// The style of the sortable headers and the filter box (part of the page's style sheet).
pub const STYLE: &str = r#"th.sortable { cursor: pointer; user-select: none; }
th.sortable::after { content: " \2195"; color: #a3abb8; font-size: 11px; }
th[aria-sort="ascending"]::after { content: " \25B2"; color: #1f5fa8; }
th[aria-sort="descending"]::after { content: " \25BC"; color: #1f5fa8; }
div.filter { margin: 6px 0 2px; }
div.filter input { font: inherit; padding: 2px 6px; width: 260px; }
"#;

/// The `<script>` element every page carries once, at the end of its body.
pub fn script() -> String {
    format!("<script id=\"{SCRIPT_ID}\">\n{}</script>\n", SOURCE.replace("@ROWS@", &FILTER_ROWS.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_is_short_self_contained_and_cannot_end_early() {
        let s = script();
        assert!(s.lines().count() < 100, "{} lines", s.lines().count());
        assert_eq!(s.matches("</script>").count(), 1, "only its own end tag");
        assert!(!s.contains("@ROWS@") && s.contains(&format!("> {FILTER_ROWS}")));
        for banned in ["http:", "https:", "fetch(", "XMLHttpRequest", "import ", "src="] {
            assert!(!s.contains(banned), "the script loads nothing: {banned}");
        }
    }
}
