//! A skeleton drawn flat as SVG: the turtle's branches seen from the south (x to the right,
//! height up), its dots as small discs. For the seed's 2D examples (Koch, Sierpinski,
//! phyllotaxis) that is the whole figure; for a tree, its side view.

use std::fmt::Write;

use crate::growers::skeleton::Skeleton;

/// SVG text of `sk`, fitted into a `size` x `size` pixel page with a margin.
pub fn skeleton_svg(sk: &Skeleton, size: f64, title: &str) -> String {
    let (lo, hi) = sk.bounds();
    let (w, h) = ((hi[0] - lo[0]).max(1e-9), (hi[2] - lo[2]).max(1e-9));
    let margin = size * 0.05;
    let s = (size - 2.0 * margin) / w.max(h);
    let x = |v: f64| margin + (v - lo[0]) * s;
    let y = |v: f64| size - margin - (v - lo[2]) * s;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size}\" height=\"{size}\" \
         viewBox=\"0 0 {size} {size}\">\n<title>{}</title>\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>",
        escape(title)
    );
    out.push_str("<g stroke=\"#3a2a1a\" stroke-linecap=\"round\" fill=\"none\">\n");
    let stroke = (size / 800.0).max(0.5);
    for n in &sk.nodes {
        if let Some(p) = n.parent {
            let a = sk.nodes[p as usize].at;
            let _ = writeln!(
                out,
                "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke-width=\"{:.2}\"/>",
                x(a[0]),
                y(a[2]),
                x(n.at[0]),
                y(n.at[2]),
                (n.radius * 2.0 * s).max(stroke)
            );
        }
    }
    out.push_str("</g>\n<g fill=\"#4a7a3a\">\n");
    for p in &sk.polygons {
        let pts: Vec<String> = p
            .corners
            .iter()
            .map(|c| format!("{:.2},{:.2}", x(c[0]), y(c[2])))
            .collect();
        let _ = writeln!(out, "<polygon points=\"{}\"/>", pts.join(" "));
    }
    let r = (size / 300.0).max(1.0);
    for d in &sk.dots {
        let _ = writeln!(
            out,
            "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"{r:.2}\"/>",
            x(d[0]),
            y(d[2])
        );
    }
    out.push_str("</g>\n</svg>\n");
    out
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
