//! The working rooms a batch keeps between calls: each task of a call borrows the lanes'
//! scratch (rows of the solve, states, stages) from its batch and gives it back at its end,
//! so the next call allocates, zeroes and faults in nothing. Allocating them afresh was
//! about a tenth of a short call on one thread and more on two (`docs/ensembles.md`).

use std::any::Any;
use std::fmt;
use std::ops::{Deref, DerefMut};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// A batch's kept rooms, of any types (one per kind of call and lane width). At most one
/// room of a type per thread of the current rayon pool is kept; the rest are dropped.
/// A clone of a batch starts with none.
#[derive(Default)]
pub(crate) struct Rooms(Mutex<Vec<Box<dyn Any + Send>>>);

impl Rooms {
    /// A kept room of type `S`, or `make()`'s when none is kept; it goes back when dropped.
    /// Whoever uses a room writes what they read: a kept room holds the last call's numbers.
    pub(crate) fn take<S: Any + Send>(&self, make: impl FnOnce() -> S) -> Room<'_, S> {
        let kept = {
            let mut rooms = self.lock();
            rooms.iter().position(|r| r.is::<S>()).map(|i| rooms.swap_remove(i))
        };
        let room = kept.and_then(|r| r.downcast::<S>().ok()).unwrap_or_else(|| Box::new(make()));
        Room { room: Some(room), rooms: self }
    }

    /// How many rooms are kept.
    pub(crate) fn len(&self) -> usize {
        self.lock().len()
    }

    fn lock(&self) -> MutexGuard<'_, Vec<Box<dyn Any + Send>>> {
        // A panic while the list was held leaves it whole (pushes and removes only).
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl Clone for Rooms {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl fmt::Debug for Rooms {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Rooms({} kept)", self.len())
    }
}

/// A room borrowed from [`Rooms`]: derefs to the `S`, and goes back into its `Rooms` when
/// dropped.
pub(crate) struct Room<'a, S: Any + Send> {
    /// Always `Some` until dropped.
    room: Option<Box<S>>,
    rooms: &'a Rooms,
}

impl<S: Any + Send> Deref for Room<'_, S> {
    type Target = S;
    fn deref(&self) -> &S {
        self.room.as_deref().expect("a room until dropped")
    }
}

impl<S: Any + Send> DerefMut for Room<'_, S> {
    fn deref_mut(&mut self) -> &mut S {
        self.room.as_deref_mut().expect("a room until dropped")
    }
}

impl<S: Any + Send> Drop for Room<'_, S> {
    fn drop(&mut self) {
        let Some(room) = self.room.take() else { return };
        let mut rooms = self.rooms.lock();
        if rooms.iter().filter(|r| r.is::<S>()).count() < rayon::current_num_threads() {
            rooms.push(room);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_room_comes_back_and_is_lent_again_by_type() {
        let rooms = Rooms::default();
        {
            let mut a = rooms.take(|| vec![1.0f64; 3]);
            a[0] = 7.0;
            let b = rooms.take(|| 5u32);
            assert_eq!((a.len(), *b), (3, 5));
        }
        assert_eq!(rooms.len(), 2);
        // The kept vector, with what its last user wrote, not a new one.
        let a = rooms.take(|| vec![0.0f64; 1]);
        assert_eq!(*a, vec![7.0, 1.0, 1.0]);
        assert_eq!(rooms.len(), 1);
        drop(a);
        assert_eq!(format!("{rooms:?}"), "Rooms(2 kept)");
        assert_eq!(rooms.clone().len(), 0);
    }

    #[test]
    fn no_more_rooms_of_a_type_are_kept_than_threads() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("a pool");
        pool.install(|| {
            let rooms = Rooms::default();
            let held: Vec<_> = (0..5).map(|k| rooms.take(move || k)).collect();
            drop(held);
            assert_eq!(rooms.len(), 2);
        });
    }
}
