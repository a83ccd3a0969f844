// planning_worker.hpp -- the background work of a Performance (private to
// src/perform): finishing and planning a score, rebuilding the character
// (100 ms or more), run by a worker thread beside the physics loop, which
// hands jobs over and takes results back through lock-free queues only.
#pragma once

#include "ictus/base/spsc_queue.hpp"
#include "ictus/perform/commands.hpp"

#include <atomic>
#include <memory>
#include <string>
#include <thread>

namespace ictus
{

// One piece of background work: the job's inputs (copies, so that it can run
// while the physics thread goes on) and, once run(), its result. The same
// object goes to the worker and back.
class Work
{
  public:
    enum class Kind {
        play,      // finish the statements (none: the current score), plan, start
        replan,    // plan the current score on a new frame; a plan under way goes on
        score_rig, // the character again (a grip change), from a pose
        clip_rig,  // clip mode: the character and its reference again, then play
        tempo,     // the score under way at a new tempo from its first beat not yet under way
        disposal,  // nothing to run: what it holds is freed off the physics thread
    };
    explicit Work(Kind kind) : kind(kind) {}
    virtual ~Work() = default;
    Work(const Work &) = delete;
    Work &operator=(const Work &) = delete;
    // Builds the result; an exception leaves `error` set and no result. A
    // cancelled play is not built.
    void run();
    // A play (or a clip's rebuild, which plays when installed) is cancelled
    // by a stop that came after it was asked for: its plan is not installed,
    // nothing starts (Performance::apply counts the stops).
    bool cancelled() const
    {
        return stop_count && stop_count->load(std::memory_order_acquire) != stops;
    }
    // Whether this job, queued after `earlier`, makes it pointless (a drum
    // slider's 20 changes a second plan once).
    bool supersedes(const Work &earlier) const;

    const Kind kind;
    Command origin;    // who asked: a refusal found later is answered to them
    std::string error; // not empty: refused, nothing changes
    // The performance's count of stops when the work was asked for (play,
    // clip_rig), and that count (null: the work cannot be cancelled).
    const std::atomic<long> *stop_count = nullptr;
    long stops = 0;

  protected:
    virtual void build() = 0;
    virtual void clear_result() = 0;
};

// Work that only carries something the physics thread replaced (an old rig,
// an old plan) to the worker, which frees it.
template <typename T> class Disposal : public Work
{
  public:
    explicit Disposal(std::unique_ptr<T> item) : Work(Kind::disposal), item_(std::move(item)) {}

  protected:
    void build() override {}
    void clear_result() override {}

  private:
    std::unique_ptr<T> item_;
};

// The worker thread: takes jobs, keeps only the last of a kind that a later
// one supersedes, runs them in order and hands the results back; what the
// physics thread has replaced is freed here too. Queues only: the physics
// thread never waits for it.
class PlanningWorker
{
  public:
    static constexpr int kQueue = 64;
    PlanningWorker();
    ~PlanningWorker();
    PlanningWorker(const PlanningWorker &) = delete;
    PlanningWorker &operator=(const PlanningWorker &) = delete;
    // False when kQueue jobs are already waiting (the job is dropped).
    bool submit(std::unique_ptr<Work> job);
    // A job run, oldest first; nullptr when none is back.
    std::unique_ptr<Work> take();
    // Frees `old` on the worker thread (here, when its queue is full).
    void discard(std::unique_ptr<Work> old);
    bool pending() const { return outstanding_.load() > 0; }

  private:
    void loop();
    SpscQueue<Work *, kQueue> jobs_;
    SpscQueue<Work *, kQueue> results_;
    SpscQueue<Work *, kQueue> garbage_;
    std::atomic<bool> running_{true};
    std::atomic<long> outstanding_{0};
    std::thread thread_;
};

} // namespace ictus
