// Scratch measurement (not committed): quick-xml's checked attributes vs alba-xml's parse.
use std::time::Instant;
#[test]
fn measure() {
    for n in [10_000usize, 20_000, 40_000] {
        let mut s = String::from("<net");
        for i in 0..n {
            s.push_str(&format!(" a{i}=\"v\""));
        }
        s.push_str("/>");
        let mut r = quick_xml::reader::Reader::from_str(&s);
        let t = Instant::now();
        if let Ok(quick_xml::events::Event::Empty(e)) = r.read_event() {
            let c = e.attributes().filter(|a| a.is_ok()).count();
            assert_eq!(c, n);
        }
        let before = t.elapsed();
        let t = Instant::now();
        let limits = alba_xml::Limits {
            max_depth: 64,
            max_elements: 10_000_000,
            refuse_doctype: true,
        };
        let _ = alba_xml::parse(&s, &limits);
        let after = t.elapsed();
        // The same attributes spread over elements within the cap: linear.
        let mut m = String::from("<root>");
        for k in 0..(n / 250) {
            m.push_str("<e");
            for i in 0..250 {
                m.push_str(&format!(" a{i}=\"{k}\""));
            }
            m.push_str("/>");
        }
        m.push_str("</root>");
        let t = Instant::now();
        alba_xml::parse(&m, &limits).expect("parses");
        let spread = t.elapsed();
        println!(
            "N={n}: quick-xml checked {:?}; alba-xml now (refused at 257) {:?}; N attributes in elements of 250: {:?}",
            before, after, spread
        );
    }
}
