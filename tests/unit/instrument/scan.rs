//! Tests of `tapsim::instrument::scan` (src/instrument/scan.rs).

use tapsim::instrument::scan::*;

#[test]
fn a_settled_pixel_and_the_one_before_it_lie_in_one_region() {
    let regions = [
        Region {
            until_m: 0.5,
            material: 0,
            height_m: 0.0,
        },
        Region {
            until_m: 1.0,
            material: 1,
            height_m: 0.0,
        },
    ];
    // Eight pixels of 0.125: 1–3 settle on 0, 4 straddles nothing but follows 3
    // (on 0), 5–7 on 1.
    let got: Vec<Option<usize>> = (0..8)
        .map(|i| settled_material(&regions, 1.0, 8, i))
        .collect();
    assert_eq!(
        got,
        [
            None,
            Some(0),
            Some(0),
            Some(0),
            None,
            Some(1),
            Some(1),
            Some(1)
        ]
    );
}

#[test]
fn a_line_crosses_the_material_under_each_point_of_the_plane() {
    let layout = Layout {
        stripes: vec![
            Region {
                until_m: 0.4,
                material: 0,
                height_m: 0.0,
            },
            Region {
                until_m: 1.0,
                material: 1,
                height_m: 0.1,
            },
        ],
        mask: Some(Mask {
            columns: 4,
            // Top row first: y in (0.5, 1] is row 0, [0, 0.5] row 1.
            cells: vec![
                vec![None, Some((4, 0.3)), None, Some((5, 0.0))],
                vec![Some((5, 0.0)), None, None, None],
            ],
            size_m: (1.0, 1.0),
        }),
        discs: vec![
            Disc {
                centre_m: (0.35, 0.5),
                radius_m: 0.2,
                material: 2,
                height_m: 0.2,
            },
            Disc {
                centre_m: (0.5, 0.45),
                radius_m: 0.1,
                material: 3,
                height_m: -0.1,
            },
        ],
    };
    // Point by point: the last disc holding it, else the mask's cell, else its stripe.
    let under = |x: f64, y: f64| {
        let cell = if y > 0.5 {
            [None, Some((4, 0.3)), None, Some((5, 0.0))][(x * 4.0) as usize]
        } else {
            [Some((5, 0.0)), None, None, None][(x * 4.0) as usize]
        };
        layout
            .discs
            .iter()
            .rev()
            .find(|d| (x - d.centre_m.0).hypot(y - d.centre_m.1) < d.radius_m)
            .map(|d| (d.material, d.height_m))
            .or(cell)
            .unwrap_or_else(|| {
                let s = layout.stripes.iter().find(|r| x < r.until_m).unwrap();
                (s.material, s.height_m)
            })
    };
    for y in [0.0, 0.31, 0.4, 0.45, 0.49, 0.52, 0.69, 0.9] {
        let regions = layout.line_at(y, 1.0);
        assert!(regions.windows(2).all(|w| w[0].until_m < w[1].until_m));
        assert_eq!(regions.last().unwrap().until_m, 1.0);
        for i in 0..2000 {
            let x = (i as f64 + 0.5) / 2000.0;
            let r = regions.iter().find(|r| x < r.until_m).unwrap();
            assert_eq!((r.material, r.height_m), under(x, y), "x {x}, y {y}");
        }
    }
}
