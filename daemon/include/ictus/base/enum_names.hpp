// enum_names.hpp -- the names of an enum's values, one table per enum: the
// enum's to_string and its parser read the same table.
#pragma once

#include <array>
#include <cstddef>
#include <string>

namespace ictus
{

// The names of an enum whose values are 0, 1, 2, ... in declaration order.
template <std::size_t N> using EnumNames = std::array<const char *, N>;

// The name of `value`; `unknown` for a value outside the table.
template <typename Enum, std::size_t N>
const char *enum_name(const EnumNames<N> &names, Enum value, const char *unknown)
{
    const auto index = static_cast<std::size_t>(value);
    return index < N ? names[index] : unknown;
}

// The value named `text` (exactly); false, `value` untouched, when no name matches.
template <typename Enum, std::size_t N>
bool enum_from_name(const EnumNames<N> &names, const std::string &text, Enum &value)
{
    for (std::size_t i = 0; i < N; ++i)
        if (text == names[i]) {
            value = static_cast<Enum>(i);
            return true;
        }
    return false;
}

} // namespace ictus
