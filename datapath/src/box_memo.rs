//! A ray's box-test results, remembered: the restart traversals (the 2-bit history, the 1-bit
//! trail) test the same boxes again on every pass from the root, as the hardware does, and a
//! deterministic tester gives the same answer each time — so the model computes each box test
//! of a ray once and looks it up after. The traversals' results and their counted box tests
//! (`StacklessResult::box_tests`: the hardware's work) are unchanged; only the software's time
//! is saved. Reset per ray in O(1) by a generation stamp; no allocation after `new`.

/// The remembered box-test results of the current ray, by box index.
#[derive(Clone, Debug)]
pub struct BoxMemo {
    /// Per box: the generation that stored it, and the result (one cache line holds several).
    slot: Vec<(u32, Option<f64>)>,
    generation: u32,
}

impl BoxMemo {
    /// A memo for box indices `0..boxes`, holding nothing.
    pub fn new(boxes: usize) -> Self {
        BoxMemo { slot: vec![(0, None); boxes], generation: 1 }
    }

    /// Forgets every result (the next ray).
    pub fn next_ray(&mut self) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            // the stamps wrapped: clear them once every 2^32 rays
            self.slot.fill((0, None));
            self.generation = 1;
        }
    }

    /// The result for box `i`: remembered, or `test()` (then remembered). An index outside the
    /// memo is tested every time.
    #[inline]
    pub fn get_or(&mut self, i: u32, test: impl FnOnce() -> Option<f64>) -> Option<f64> {
        let generation = self.generation;
        match self.slot.get_mut(i as usize) {
            Some((s, v)) if *s == generation => *v,
            Some(slot) => {
                let v = test();
                *slot = (generation, v);
                v
            }
            None => test(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each box is tested once per ray, the remembered result is the tested one, a new ray
    /// tests again, and the stamps' wrap-around forgets everything.
    #[test]
    fn tests_once_per_ray_and_forgets_between_rays() {
        let mut m = BoxMemo::new(4);
        let mut calls = 0;
        let mut t = |m: &mut BoxMemo, i: u32, v: Option<f64>| {
            m.get_or(i, || {
                calls += 1;
                v
            })
        };
        assert_eq!(t(&mut m, 1, Some(2.0)), Some(2.0));
        assert_eq!(t(&mut m, 1, Some(9.0)), Some(2.0));
        assert_eq!(t(&mut m, 2, None), None);
        assert_eq!(t(&mut m, 2, Some(1.0)), None);
        assert_eq!(t(&mut m, 7, Some(3.0)), Some(3.0));
        assert_eq!(t(&mut m, 7, Some(4.0)), Some(4.0));
        m.next_ray();
        assert_eq!(t(&mut m, 1, Some(5.0)), Some(5.0));
        m.generation = u32::MAX;
        m.slot[3] = (u32::MAX, Some(8.0));
        assert_eq!(t(&mut m, 3, Some(6.0)), Some(8.0));
        m.next_ray();
        assert_eq!(t(&mut m, 3, Some(6.0)), Some(6.0));
        assert_eq!(calls, 6);
    }
}
