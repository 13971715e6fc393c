//! When a record is due: each output time T_k (k × interval, or one of a list)
//! is taken at the step nearest it. The state at t, from which the next step
//! takes Δt, is nearer to T_k than the next state is when T_k ≤ t + Δt/2 (a tie
//! goes to the earlier state), so a record never drifts one step late and each
//! time gives one record however many steps there are, or however few.

/// The output times of one record, and which is next.
#[derive(Clone, Debug)]
pub struct Schedule {
    times: Times,
    /// Index of the next time not yet taken.
    next: usize,
}

#[derive(Clone, Debug)]
enum Times {
    /// After every step.
    EveryStep,
    /// k × interval, k = 0, 1, …
    Interval(f64),
    /// The listed times, ascending.
    List(Vec<f64>),
}

impl Schedule {
    /// A record after every step.
    pub fn every_step() -> Self {
        Self::of(Times::EveryStep)
    }

    /// A record at k × interval (every step when the interval is 0).
    pub fn interval(interval: f64) -> Self {
        match interval > 0.0 {
            true => Self::of(Times::Interval(interval)),
            false => Self::every_step(),
        }
    }

    /// A record at each of `times` (in any order).
    pub fn list(mut times: Vec<f64>) -> Self {
        times.sort_by(f64::total_cmp);
        times.dedup();
        Self::of(Times::List(times))
    }

    fn of(times: Times) -> Self {
        Schedule { times, next: 0 }
    }

    /// The k-th output time (none past the end of a list).
    fn time(&self, k: usize) -> Option<f64> {
        match &self.times {
            Times::EveryStep => Some(0.0),
            Times::Interval(interval) => Some(k as f64 * interval),
            Times::List(times) => times.get(k).copied(),
        }
    }

    /// Whether the state at `t` is the record of an output time, the next step
    /// taking `next_dt` (none: no step follows, and every time up to `t` within
    /// `tolerance` is taken now). The times it takes are passed.
    pub fn take(&mut self, t: f64, next_dt: Option<f64>, tolerance: f64) -> bool {
        if matches!(self.times, Times::EveryStep) {
            return true;
        }
        let reach = match next_dt {
            Some(dt) => t + 0.5 * dt,
            None => t + tolerance,
        };
        let mut taken = false;
        while self.time(self.next).is_some_and(|tk| tk <= reach) {
            self.next += 1;
            taken = true;
        }
        taken
    }

    /// The next time not yet taken (a checkpoint keeps it), if any.
    pub fn next_time(&self) -> Option<f64> {
        self.time(self.next)
    }

    /// Continue from a checkpoint: the times before `next` were taken.
    pub fn resume_at(&mut self, next: f64) {
        self.next = match &self.times {
            Times::EveryStep => 0,
            Times::Interval(interval) => (next / interval).round() as usize,
            Times::List(times) => times.partition_point(|&tk| tk < next),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps of `dt` summed from 0 (with their round-off): the step of each
    /// record.
    fn records(mut s: Schedule, dt: f64, steps: usize) -> Vec<usize> {
        let mut t = 0.0;
        let mut taken = Vec::new();
        for n in 0..steps {
            if s.take(t, Some(dt), 0.0) {
                taken.push(n);
            }
            t += dt;
        }
        if s.take(t, None, 1e-12) {
            taken.push(steps);
        }
        taken
    }

    #[test]
    fn each_time_at_its_nearest_step_once() {
        // 1e-5 summed 5,000 times: the times 1e-3 k fall on steps 100 k, and
        // round-off never makes a record a step late.
        let taken = records(Schedule::interval(1e-3), 1e-5, 5_000);
        assert_eq!(taken, (0..=50).map(|k| 100 * k).collect::<Vec<_>>());
        // Steps of 0.3 against times 0.5 k: nearest steps 0, 2 (0.6), 3 (0.9;
        // 1.0 is 0.1 away), 5 (1.5), 7 (2.1; 2.0 is 0.1 from 2.1, 0.2 from 1.8).
        let taken = records(Schedule::interval(0.5), 0.3, 7);
        assert_eq!(taken, vec![0, 2, 3, 5, 7]);
    }

    #[test]
    fn times_closer_than_a_step_give_one_record() {
        let taken = records(Schedule::list(vec![0.3, 0.25, 0.29, 0.95]), 0.2, 5);
        assert_eq!(taken, vec![1, 5]);
    }

    #[test]
    fn a_resumed_schedule_goes_on_as_the_uninterrupted_one() {
        let mut s = Schedule::interval(0.25);
        assert!(s.take(0.0, Some(0.1), 0.0));
        assert!(!s.take(0.1, Some(0.1), 0.0));
        assert!(s.take(0.2, Some(0.1), 0.0));
        let mut resumed = Schedule::interval(0.25);
        resumed.resume_at(s.next_time().unwrap());
        assert_eq!(resumed.next, s.next);
        let mut listed = Schedule::list(vec![0.1, 0.5]);
        listed.resume_at(0.5);
        assert_eq!(listed.next_time(), Some(0.5));
    }
}
