// The planning worker of a Performance (planning_worker.hpp).
#include "planning_worker.hpp"

#include <chrono>
#include <deque>
#include <exception>

namespace ictus
{

void Work::run()
{
    if (kind == Kind::play && cancelled())
        return; // a stop came first: nothing to plan
    try {
        build();
    } catch (const std::exception &e) {
        error = e.what();
        clear_result();
    }
}

bool Work::supersedes(const Work &earlier) const
{
    if (earlier.kind == Kind::replan)
        return kind == Kind::replan || kind == Kind::play;
    return earlier.kind != Kind::play && kind == earlier.kind;
}

PlanningWorker::PlanningWorker() : thread_([this] { loop(); }) {}

PlanningWorker::~PlanningWorker()
{
    running_ = false;
    thread_.join();
    Work *w;
    while (jobs_.pop(w))
        delete w;
    while (results_.pop(w))
        delete w;
    while (garbage_.pop(w))
        delete w;
}

bool PlanningWorker::submit(std::unique_ptr<Work> job)
{
    if (!jobs_.push(job.get()))
        return false;
    job.release();
    outstanding_.fetch_add(1);
    return true;
}

std::unique_ptr<Work> PlanningWorker::take()
{
    Work *w = nullptr;
    if (!results_.pop(w))
        return nullptr;
    outstanding_.fetch_sub(1);
    return std::unique_ptr<Work>(w);
}

void PlanningWorker::discard(std::unique_ptr<Work> old)
{
    if (garbage_.push(old.get()))
        old.release(); // else freed here, by the caller
}

void PlanningWorker::loop()
{
    std::deque<Work *> queued;
    while (running_.load()) {
        Work *w;
        while (garbage_.pop(w))
            delete w;
        while (jobs_.pop(w))
            queued.push_back(w);
        for (size_t i = 0; i < queued.size();) {
            bool superseded = false;
            for (size_t k = i + 1; k < queued.size() && !superseded; ++k)
                superseded = queued[k]->supersedes(*queued[i]);
            if (superseded) {
                delete queued[i];
                queued.erase(queued.begin() + static_cast<long>(i));
                outstanding_.fetch_sub(1);
            } else {
                ++i;
            }
        }
        if (queued.empty()) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
            continue;
        }
        std::unique_ptr<Work> job(queued.front());
        queued.pop_front();
        job->run();
        while (running_.load() && !results_.push(job.get()))
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        if (running_.load())
            job.release();
    }
    for (Work *q : queued)
        delete q;
}

} // namespace ictus
