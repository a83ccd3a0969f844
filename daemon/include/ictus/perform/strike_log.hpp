// strike_log.hpp -- the one way strikes reach a file. The detector reports a
// strike when its contact ends, so a long contact of one hand can end after a
// later, shorter one of the other: StrikeOrder puts them back in onset order
// (seq) without allocating, and StrikeLog keeps a run's strikes for the
// offline verbs. `track`, `render` and `run` all write strikes.csv through
// these, in the same order (docs/osc.md).
#pragma once

#include "ictus/sim/strike_detector.hpp"

#include <array>
#include <iosfwd>
#include <vector>

namespace ictus
{

class StrikeOrder
{
  public:
    // A strike the detector just reported. Held until release() or flush();
    // if kCapacity already wait (never with two hands: at most one strike
    // waits for the other hand's contact), the lowest is let go first.
    template <typename Emit> void push(const StrikeEvent &event, Emit &&emit)
    {
        if (held_ == kCapacity) {
            const int k = lowest();
            emit(pending_[k]);
            remove(k);
        }
        pending_[held_++] = event;
    }
    // Emits, in seq order, every held strike numbered below `first_open_seq`
    // (StrikeDetector::first_open_seq(): all those before it have ended).
    template <typename Emit> void release(long first_open_seq, Emit &&emit)
    {
        for (;;) {
            const int k = lowest();
            if (k < 0 || pending_[k].seq >= first_open_seq)
                return;
            emit(pending_[k]);
            remove(k);
        }
    }
    // Emits everything held, in seq order (end of a run).
    template <typename Emit> void flush(Emit &&emit) { release(kNoLimit, emit); }
    int held() const { return held_; }

  private:
    static constexpr int kCapacity = 16;
    static constexpr long kNoLimit = 0x7fffffffffffffffL;
    int lowest() const
    {
        int k = -1;
        for (int i = 0; i < held_; ++i)
            if (k < 0 || pending_[i].seq < pending_[k].seq)
                k = i;
        return k;
    }
    void remove(int k)
    {
        for (int i = k; i + 1 < held_; ++i)
            pending_[i] = pending_[i + 1];
        --held_;
    }
    std::array<StrikeEvent, kCapacity> pending_{};
    int held_ = 0;
};

// A run's strikes in onset order, kept in memory (a few per second) and
// written when the run ends, so that the physics loop never writes a file.
class StrikeLog
{
  public:
    // After each physics step: the n strikes that step ended, and the
    // detector's first_open_seq() after it.
    void add(const StrikeEvent *events, int n, long first_open_seq);
    // A strike that StrikeDetector::flush() ended (end of a run); then finish().
    void add_flushed(const StrikeEvent &event);
    // Takes in every strike still held, in order.
    void finish();
    const std::vector<StrikeEvent> &strikes() const { return strikes_; }
    long bounces() const;
    // strikes.csv and the events file (sim/strike_event.hpp); false on a write error.
    bool write_csv(std::ostream &out) const;
    bool write_events(std::ostream &out) const;

  private:
    StrikeOrder order_;
    std::vector<StrikeEvent> strikes_;
};

} // namespace ictus
