use super::*;

/// A rooted tree whose non-root vertices carry a colour: 0 the explicit part, 1 the
/// implicit part (the root's colour does not matter, the weights being shared).
#[derive(Clone)]
struct Tree(Vec<(usize, Tree)>);

impl Tree {
    fn order(&self) -> usize {
        1 + self.0.iter().map(|(_, t)| t.order()).sum::<usize>()
    }

    /// The tree's density γ(t) = |t|·Π γ(children).
    fn density(&self) -> f64 {
        self.order() as f64 * self.0.iter().map(|(_, t)| t.density()).product::<f64>()
    }
}

/// Every coloured tree with `n` vertices (children in every order: repeats are harmless).
fn trees(n: usize) -> Vec<Tree> {
    if n == 1 {
        return vec![Tree(Vec::new())];
    }
    let mut out = Vec::new();
    // Ordered compositions of n − 1 into child sizes.
    fn compositions(rest: usize, prefix: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if rest == 0 {
            out.push(prefix.clone());
            return;
        }
        for p in 1..=rest {
            prefix.push(p);
            compositions(rest - p, prefix, out);
            prefix.pop();
        }
    }
    let mut comps = Vec::new();
    compositions(n - 1, &mut Vec::new(), &mut comps);
    for comp in comps {
        let mut partial: Vec<Vec<(usize, Tree)>> = vec![Vec::new()];
        for &size in &comp {
            let mut next = Vec::new();
            for children in &partial {
                for sub in trees(size) {
                    for colour in 0..2 {
                        let mut c = children.clone();
                        c.push((colour, sub.clone()));
                        next.push(c);
                    }
                }
            }
            partial = next;
        }
        out.extend(partial.into_iter().map(Tree));
    }
    out
}

/// The stage vector of a tree: the product over its children of A_colour·(child's vector).
fn stage_vector<const N: usize>(t: &Tree, parts: &[[[f64; N]; N]; 2]) -> [f64; N] {
    let mut g = [1.0; N];
    for (colour, child) in &t.0 {
        let v = stage_vector(child, parts);
        let a = &parts[*colour];
        for (i, gi) in g.iter_mut().enumerate() {
            *gi *= (0..N).map(|j| a[i][j] * v[j]).sum::<f64>();
        }
    }
    g
}

/// The largest residual of the order conditions of orders 1..=p for weights w.
fn residual<const N: usize>(tab: &Tableau<N>, w: &[f64; N], p: usize) -> f64 {
    let mut implicit = tab.ai;
    for (i, row) in implicit.iter_mut().enumerate().skip(1) {
        row[i] = tab.gamma;
    }
    let parts = [tab.ae, implicit];
    let mut worst: f64 = 0.0;
    for n in 1..=p {
        for t in trees(n) {
            let g = stage_vector(&t, &parts);
            let phi: f64 = w.iter().zip(&g).map(|(a, b)| a * b).sum();
            worst = worst.max((phi - 1.0 / t.density()).abs());
        }
    }
    worst
}

fn check<const N: usize>(tab: &Tableau<N>, tol: f64) {
    let p = tab.order as usize;
    let main = residual(tab, &tab.b, p);
    let embedded = residual(tab, &tab.bhat, p - 1);
    assert!(main < tol, "order {p} conditions: residual {main:e}");
    assert!(embedded < tol, "order {} conditions of the embedding: residual {embedded:e}", p - 1);
    // A tree one order higher is not satisfied by the main weights (the order is exact).
    assert!(residual(tab, &tab.b, p + 1) > 1e3 * tol, "order {p} is not the method's order");
    // c = A·1 for both parts, and the implicit part is stiffly accurate.
    for i in 0..N {
        let e: f64 = tab.ae[i].iter().sum();
        let im: f64 = tab.ai[i].iter().sum::<f64>() + if i > 0 { tab.gamma } else { 0.0 };
        assert!((e - tab.c[i]).abs() < tol && (im - tab.c[i]).abs() < tol, "row {i}");
    }
    for j in 0..N - 1 {
        assert!((tab.ai[N - 1][j] - tab.b[j]).abs() < tol, "last implicit row, column {j}");
    }
    assert_eq!(tab.b[N - 1], tab.gamma);
}

#[test]
fn ark436_satisfies_every_coupled_order_condition_up_to_four() {
    // Largest residual measured: 1.1e-16; a fifth-order tree misses by 9.2e-3.
    check(&ARK436, 2e-15);
}

#[test]
fn ark548_satisfies_every_coupled_order_condition_up_to_five() {
    // Largest residual measured: 2.2e-16; a sixth-order tree misses by 4.3e-3.
    check(&ARK548, 2e-15);
}
