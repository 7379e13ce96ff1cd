//! The Metro-style refit scheduler: top priorities plus random picks, vertex budget, no
//! starvation, deterministic for a seed.

use hikari_bvh::{RefitScheduler, ThrottleSettings};

fn scheduler(n: usize, seed: u64) -> RefitScheduler {
    let mut s = RefitScheduler::new(ThrottleSettings {
        seed,
        ..Default::default()
    });
    for i in 0..n {
        s.register(1000 + i);
    }
    s
}

#[test]
fn picks_the_top_sixteen_then_four_random_with_nonzero_priority() {
    let mut s = scheduler(100, 1);
    for i in 0..60 {
        // Higher id, higher priority; ids 60..100 never move.
        s.touch(i, true, 1.0, 100.0 - i as f32);
    }
    let batch = s.select();
    assert_eq!(batch.ids.len(), 20);
    assert_eq!(batch.random_picks, 4);
    let top: Vec<usize> = (44..60).rev().collect();
    assert_eq!(&batch.ids[..16], top.as_slice());
    for &r in &batch.ids[16..] {
        assert!(
            r < 44,
            "random pick {r} must come from the remaining non-zero set"
        );
    }
    assert_eq!(batch.outdated, 60 - 20);
    for &i in &batch.ids {
        assert_eq!(s.priority(i), 0.0);
    }
}

#[test]
fn visible_near_objects_outrank_hidden_or_distant_ones() {
    let mut s = scheduler(3, 2);
    s.touch(0, true, 1.0, 5.0);
    s.touch(1, false, 1.0, 5.0);
    s.touch(2, true, 1.0, 500.0);
    assert!(s.priority(0) > s.priority(1));
    assert!(s.priority(0) > s.priority(2));
    assert!(s.priority(1) > 0.0 && s.priority(2) > 0.0);
}

#[test]
fn vertex_budget_is_respected() {
    let mut s = RefitScheduler::new(ThrottleSettings {
        vertex_budget: 10_000,
        ..Default::default()
    });
    for _ in 0..50 {
        s.register(3000);
    }
    for i in 0..50 {
        s.touch(i, true, 1.0, 10.0);
    }
    let b = s.select();
    assert_eq!(b.ids.len(), 3);
    assert!(b.vertices <= 10_000);
    // A single object over the budget is still refit when it is the first pick.
    let mut s = RefitScheduler::new(ThrottleSettings {
        vertex_budget: 100,
        ..Default::default()
    });
    let big = s.register(5000);
    s.touch(big, true, 1.0, 1.0);
    assert_eq!(s.select().ids, vec![big]);
}

#[test]
fn nothing_starves_and_the_queue_stays_balanced() {
    let mut s = scheduler(200, 3);
    let mut last_refit = vec![0usize; 200];
    let mut worst_wait = 0;
    for frame in 1..=400 {
        // Every object deforms every frame; a few near ones dominate the priority.
        for i in 0..200 {
            let distance = if i < 10 { 2.0 } else { 50.0 + i as f32 };
            s.touch(i, i % 2 == 0, 1.0, distance);
        }
        let b = s.select();
        assert!(b.ids.len() <= 20);
        for &i in &b.ids {
            worst_wait = worst_wait.max(frame - last_refit[i]);
            last_refit[i] = frame;
        }
        assert_eq!(b.outdated, 200 - b.ids.len());
    }
    assert!(
        last_refit.iter().all(|&f| f > 0),
        "every object was refit at least once"
    );
    assert!(worst_wait < 200, "longest wait {worst_wait} frames");
}

#[test]
fn same_seed_same_choices() {
    let run = |seed| {
        let mut s = scheduler(80, seed);
        (0..10)
            .map(|_| {
                for i in 0..80 {
                    s.touch(i, true, 1.0, 10.0 + i as f32);
                }
                s.select().ids
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}
