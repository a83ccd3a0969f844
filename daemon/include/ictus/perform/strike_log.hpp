// strike_log.hpp -- the one way strikes reach a file, in onset order (seq).
// The detector reports a strike when its contact ends, so a strike of one
// hand can end after later ones of the other (a stick resting on the head
// while the other plays). StrikeLog (track, render) keeps a run's strikes in
// memory and sorts them at the end; StrikeOrder (run's physics thread, no
// allocation) holds each strike until every earlier contact has ended. Both
// feed write_strike_csv_row (sim/strike_event.hpp). docs/osc.md.
#pragma once

#include "ictus/sim/strike_event.hpp"

#include <array>
#include <iosfwd>
#include <limits>
#include <vector>

namespace ictus
{

class StrikeOrder
{
  public:
    static constexpr int kCapacity = 256;
    // A strike the detector just reported; held until release() or flush().
    // When kCapacity strikes already wait (256 strikes of one hand while the
    // other rests on the head), the lowest is let go early and counted.
    template <typename Emit> void push(const StrikeEvent &event, Emit &&emit)
    {
        if (held_ == kCapacity) {
            const int k = lowest();
            emit(pending_[static_cast<size_t>(k)]);
            remove(k);
            ++early_;
        }
        pending_[static_cast<size_t>(held_++)] = event;
    }
    // Emits, in seq order, every held strike numbered below `first_open_seq`
    // (StrikeDetector::first_open_seq(): all strikes before it have ended).
    template <typename Emit> void release(long first_open_seq, Emit &&emit)
    {
        for (;;) {
            const int k = lowest();
            if (k < 0 || pending_[static_cast<size_t>(k)].seq >= first_open_seq)
                return;
            emit(pending_[static_cast<size_t>(k)]);
            remove(k);
        }
    }
    // Emits everything held, in seq order (end of a run).
    template <typename Emit> void flush(Emit &&emit)
    {
        release(std::numeric_limits<long>::max(), emit);
    }
    int held() const { return held_; }
    long early() const { return early_; } // let go before an earlier contact ended

  private:
    int lowest() const
    {
        int k = -1;
        for (int i = 0; i < held_; ++i)
            if (k < 0 ||
                pending_[static_cast<size_t>(i)].seq < pending_[static_cast<size_t>(k)].seq)
                k = i;
        return k;
    }
    void remove(int k)
    {
        for (int i = k; i + 1 < held_; ++i)
            pending_[static_cast<size_t>(i)] = pending_[static_cast<size_t>(i + 1)];
        --held_;
    }
    std::array<StrikeEvent, kCapacity> pending_{};
    int held_ = 0;
    long early_ = 0;
};

// A run's strikes, kept in memory (a few per second) and written when the run
// ends, so that the physics loop never writes a file.
class StrikeLog
{
  public:
    // The strikes a physics step (or StrikeDetector::flush()) ended.
    void add(const StrikeEvent *events, int n);
    // Puts them in onset order (seq); then strikes() and the writers.
    void finish();
    const std::vector<StrikeEvent> &strikes() const { return strikes_; }
    long bounces() const;
    // strikes.csv and the events file (sim/strike_event.hpp) into `out`.
    void write_csv(std::ostream &out) const;
    void write_events(std::ostream &out) const;

  private:
    std::vector<StrikeEvent> strikes_;
};

} // namespace ictus
