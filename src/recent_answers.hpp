// A thread's last few answers to a question whose answer never changes
// (not installed): creation asks the driver or recomputes once per kind of
// object rather than per object.
#pragma once

#include "vkrc/config.hpp"

#include <cstddef>

VKRC_BEGIN_NAMESPACE
namespace detail {

// Question: compared with ==; a default-made one must never be asked (a key
// of 0, such as DeviceState::id, marks an empty slot). Used through a
// thread_local, so no lock.
template <class Question, class Answer, std::size_t kept>
class RecentAnswers {
public:
    const Answer* find(const Question& question) const noexcept {
        for (const Entry& e : entries_) {
            if (e.question == question) return &e.answer;
        }
        return nullptr;
    }
    // Replaces the oldest kept answer.
    void keep(const Question& question, const Answer& answer) noexcept {
        entries_[next_++ % kept] = {question, answer};
    }

private:
    struct Entry {
        Question question{};
        Answer answer{};
    };
    Entry entries_[kept];
    std::size_t next_ = 0;
};

}  // namespace detail
VKRC_END_NAMESPACE
