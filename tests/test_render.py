"""Tables rendered for people: the HTML page the report shows inline."""

from alfa_bench.render import markdown, markdown_html


def test_markdown_html_keeps_titles_tables_lists_and_marks():
    text = ("A note on `no_emr`, **bold** and *em*.\n\n"
            + markdown([("Subset `all`", ["rank", "method"],
                         [["*honest*", ""], ["1", "a < b"]])])
            + "\n- one\n- two `x`\n")
    page = markdown_html(text, "t")
    assert page.startswith("<!DOCTYPE html>") and "<title>t</title>" in page
    assert "<p>A note on <code>no_emr</code>, <strong>bold</strong> and <em>em</em>.</p>" in page
    assert "<h3>Subset <code>all</code></h3>" in page
    assert "<tr><th>rank</th><th>method</th></tr>" in page
    assert '<td colspan="2"><em>honest</em></td>' in page     # a block's title row
    assert "<td>1</td><td>a &lt; b</td>" in page               # escaped
    assert "<ul><li>one</li><li>two <code>x</code></li></ul>" in page
