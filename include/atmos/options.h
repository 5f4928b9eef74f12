// atmos: typed model options.
//
// A model's options are one plain struct (its members carry the defaults) plus
// one OptionTable that binds each option's name to a member, with its type,
// range or choices, unit and one-line help:
//
//   struct NaiveOptions {
//       int steps = 16;
//       int light_steps = 8;
//   };
//   const OptionTable<NaiveOptions>& NaiveModel::Table() {
//       static const auto table = OptionTable<NaiveOptions>()
//           .Integer("steps", &NaiveOptions::steps, 1, 100000, "", "view-ray samples")
//           .Integer("light-steps", &NaiveOptions::light_steps, 1, 100000, "", "...");
//       return table;
//   }
//
// That table alone drives `atmos list`, the parsing and validation of
// `--model NAME:OPTION=VALUE` (the message names the model, the option and its
// range), the per-model help, the bake JSON and `--load`'s check, and the render
// cache key (OptionTable::Values: the canonical text of every option). A new
// option is one member and one row.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace atmos {

// One option as the user sees it (the type-erased view of a table row).
struct ModelOptionSpec {
    enum class Type { kInteger, kReal, kChoice, kText };
    std::string name;  // as in NAME:OPTION=VALUE
    Type type = Type::kInteger;
    std::string default_value;  // canonical text
    std::string help;
    double min = 0.0;  // integer / real: allowed range [min, max]
    double max = 0.0;
    std::vector<std::string> choices;  // kChoice
    std::string unit;                  // e.g. "km"; empty for counts and choices
    // The value shapes the tables Prepare() builds: a bake records it and
    // `--load` refuses tables baked with another value.
    bool shapes_tables = false;

    // "integer in [1, 32]", "number in [0, 1]", "one of a, b", "text".
    std::string Describe() const;
    const char* TypeName() const;  // "integer", "real", "choice", "text"
};

// The canonical text of a number: the shortest that reads back to the same
// double ("0.3", "4", "1e+06").
std::string FormatOptionNumber(double value);

// A model's options as the Markdown table of its docs page
// (docs/models/NAME.md, between its `options:begin/end` markers):
// | option | type | default | range | help |.
std::string OptionsMarkdown(const std::vector<ModelOptionSpec>& specs);

namespace detail {
// Parse `text` as the option `spec` of `model`; throw atmos::Error naming the
// model, the option and its range when it does not fit.
double ParseNumberOption(const std::string& model, const ModelOptionSpec& spec,
                         const std::string& text);
size_t ParseChoiceOption(const std::string& model, const ModelOptionSpec& spec,
                         const std::string& text);
void CheckTextOption(const std::string& model, const ModelOptionSpec& spec,
                     const std::string& text);
[[noreturn]] void FailUnknownOption(const std::string& model,
                                    const std::vector<ModelOptionSpec>& specs,
                                    const std::string& name);
}  // namespace detail

// A row reaches its member through a pointer to member (&Options::steps) or,
// for a nested member, a function returning a reference to it
// ([](Options& o) -> double& { return o.mapping.p_u; }).
template <typename Options, typename T>
T& OptionField(Options& o, T Options::*member) {
    return o.*member;
}
template <typename Options, typename Access>
auto OptionField(Options& o, Access access) -> decltype(access(o)) {
    return access(o);
}
template <typename Options, typename Access>
using OptionFieldType = std::remove_reference_t<decltype(OptionField(std::declval<Options&>(),
                                                                     std::declval<Access>()))>;

template <typename Options>
class OptionTable {
  public:
    // Cross-field validation after parsing: receives the model's name, the
    // options and the names the user gave; throws atmos::Error.
    using Rule =
        std::function<void(const std::string&, const Options&, const std::set<std::string>&)>;

    // An integer member (int, int64_t, ...) in [lo, hi].
    template <typename Access>
    OptionTable&& Integer(const char* name, Access access, double lo, double hi, const char* unit,
                          const char* help) && {
        AddNumber(ModelOptionSpec::Type::kInteger, name, access, lo, hi, unit, help);
        return std::move(*this);
    }
    // A real member in [lo, hi].
    template <typename Access>
    OptionTable&& Real(const char* name, Access access, double lo, double hi, const char* unit,
                       const char* help) && {
        AddNumber(ModelOptionSpec::Type::kReal, name, access, lo, hi, unit, help);
        return std::move(*this);
    }
    // A member of any type (an enum, a bool, a string) named by one word per value.
    template <typename Access>
    OptionTable&& Choice(
        const char* name, Access access,
        std::vector<std::pair<std::string, OptionFieldType<Options, Access>>> choices,
        const char* help) && {
        ModelOptionSpec spec = Base(name, ModelOptionSpec::Type::kChoice, "", help);
        for (const auto& c : choices) spec.choices.push_back(c.first);
        Add(
            std::move(spec),
            [access, choices](Options* o, const std::string& model, const ModelOptionSpec& s,
                              const std::string& text) {
                OptionField(*o, access) = choices[detail::ParseChoiceOption(model, s, text)].second;
            },
            [access, choices](Options o) {
                for (const auto& c : choices) {
                    if (c.second == OptionField(o, access)) return c.first;
                }
                return std::string("?");
            });
        return std::move(*this);
    }
    // A text member (e.g. a file name); empty by default, never empty when given.
    template <typename Access>
    OptionTable&& Text(const char* name, Access access, const char* help) && {
        Add(
            Base(name, ModelOptionSpec::Type::kText, "", help),
            [access](Options* o, const std::string& model, const ModelOptionSpec& s,
                     const std::string& text) {
                detail::CheckTextOption(model, s, text);
                OptionField(*o, access) = text;
            },
            [access](Options o) { return std::string(OptionField(o, access)); });
        return std::move(*this);
    }
    // Marks the row added last as one that shapes the precomputed tables.
    OptionTable&& ShapesTables() && {
        specs_.back().shapes_tables = true;
        return std::move(*this);
    }
    // A rule between options (see Rule).
    OptionTable&& Validate(Rule rule) && {
        rules_.push_back(std::move(rule));
        return std::move(*this);
    }

    const std::vector<ModelOptionSpec>& Specs() const { return specs_; }

    // The options `given` (name -> text) on top of the defaults; throws
    // atmos::Error for an unknown name, a value outside its type or range, or a
    // broken rule.
    Options Parse(const std::string& model, const std::map<std::string, std::string>& given) const {
        Options o{};
        std::set<std::string> names;
        for (const auto& [name, text] : given) {
            size_t i = 0;
            while (i < specs_.size() && specs_[i].name != name) ++i;
            if (i == specs_.size()) detail::FailUnknownOption(model, specs_, name);
            rows_[i].set(&o, model, specs_[i], text);
            names.insert(name);
        }
        for (const Rule& rule : rules_) rule(model, o, names);
        return o;
    }

    // Checks options made in code (not parsed): every value within its row's
    // range or choices, and the rules (with no names given).
    void Check(const std::string& model, const Options& o) const {
        Options scratch{};
        for (const Row& row : rows_) {
            const size_t i = static_cast<size_t>(&row - rows_.data());
            row.set(&scratch, model, specs_[i], row.get(o));
        }
        for (const Rule& rule : rules_) rule(model, o, {});
    }

    // Every option's canonical text, in table order.
    std::vector<std::pair<std::string, std::string>> Values(const Options& o) const {
        std::vector<std::pair<std::string, std::string>> v;
        for (size_t i = 0; i < rows_.size(); ++i) v.emplace_back(specs_[i].name, rows_[i].get(o));
        return v;
    }

  private:
    using Setter = std::function<void(Options*, const std::string&, const ModelOptionSpec&,
                                      const std::string&)>;
    using Getter = std::function<std::string(Options)>;
    struct Row {
        Setter set;
        Getter get;
    };

    static ModelOptionSpec Base(const char* name, ModelOptionSpec::Type type, const char* unit,
                                const char* help) {
        ModelOptionSpec spec;
        spec.name = name;
        spec.type = type;
        spec.unit = unit;
        spec.help = help;
        return spec;
    }
    template <typename Access>
    void AddNumber(ModelOptionSpec::Type type, const char* name, Access access, double lo,
                   double hi, const char* unit, const char* help) {
        using T = OptionFieldType<Options, Access>;
        ModelOptionSpec spec = Base(name, type, unit, help);
        spec.min = lo;
        spec.max = hi;
        Add(
            std::move(spec),
            [access](Options* o, const std::string& model, const ModelOptionSpec& s,
                     const std::string& text) {
                OptionField(*o, access) = static_cast<T>(detail::ParseNumberOption(model, s, text));
            },
            [access](Options o) {
                return FormatOptionNumber(static_cast<double>(OptionField(o, access)));
            });
    }
    void Add(ModelOptionSpec spec, Setter set, Getter get) {
        spec.default_value = get(Options{});
        specs_.push_back(std::move(spec));
        rows_.push_back({std::move(set), std::move(get)});
    }

    std::vector<ModelOptionSpec> specs_;
    std::vector<Row> rows_;
    std::vector<Rule> rules_;
};

// The options struct and table of models without options.
struct NoOptions {};
const OptionTable<NoOptions>& NoOptionTable();

}  // namespace atmos
