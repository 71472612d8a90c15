#pragma once
/**
 * \file param_spec.hpp
 * \brief What a parameter is (a row of the parameter table: key, type, default, range, unit,
 *        description, live-tunable, the member it is) and the controller's rows, the keys of
 *        AicParams, with their range checks. ROS-free; independent of the node's parameters
 *        (the node's rows and the whole table: include/jackal_aic/params/param_schema.hpp).
 */

#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace params
{
struct NodeParams;  // include/jackal_aic/params/node_params.hpp

/// Largest loop rate the node accepts for either timer [Hz] (ParamSpec::node_max of the rates;
/// the core's own bound is kMaxRate).
constexpr double kMaxLoopRate = 10000.0;

/// Type of a parameter's value (as in the YAML file and on the parameter server).
enum class ParamType
{
  kDouble,      ///< a number (an integer in the YAML is accepted)
  kInt,         ///< an integer
  kBool,        ///< true / false
  kString,      ///< a string, optionally one of ParamSpec::choices
  kDoubleList,  ///< a list of numbers
  kStringList   ///< a list of strings
};

/// A parameter's value; the alternative matches ParamType (kDouble -> double, ...).
using ParamValue = std::variant<bool, int, double, std::string, std::vector<double>, std::vector<std::string>>;

/// Who reads a parameter.
enum class ParamScope
{
  kController,  ///< a member of AicParams: the node and the tools (aic_analyze, closed_loop_run, ...)
  kNode         ///< a node-only member of NodeParams (ignored by the tools)
};

/// A set of belief models (AicParams::belief_model): bit beliefModelBit(m) for each model m in it.
using BeliefModelSet = unsigned;

/// The bit of one belief model in a BeliefModelSet.
constexpr BeliefModelSet beliefModelBit(BeliefModel model)
{
  return 1u << static_cast<unsigned>(model);
}

/// Every belief model: the set of a key every controller reads (the default of a row).
constexpr BeliefModelSet kAllBeliefModels =
    beliefModelBit(BeliefModel::kGoal) | beliefModelBit(BeliefModel::kUnbiased) | beliefModelBit(BeliefModel::kRobot);

/// The two models with the thesis's linear belief dynamics (eq. 3-15) and its stages around the
/// action (goal, unbiased): the keys of those dynamics and stages, which the robot model does not read.
constexpr BeliefModelSet kLinearBeliefModels =
    beliefModelBit(BeliefModel::kGoal) | beliefModelBit(BeliefModel::kUnbiased);

/// The robot model alone: the keys of its generative model (RobotModelParams), which the other two do not read.
constexpr BeliefModelSet kRobotBeliefModel = beliefModelBit(BeliefModel::kRobot);

/**
 * \brief The models of a set by name, in enum order, joined with ", " and a final " and ":
 *        "goal and unbiased", "robot", "goal, unbiased and robot"; "" for the empty set.
 */
std::string beliefModelsText(BeliefModelSet models);

/**
 * \brief One row of the schema.
 *
 * Range: a number (each element of a list) must be finite and lie in [min, max], or in
 * (min, max] when min_exclusive; max = +infinity means "no upper bound" (still finite).
 * kInt: an integer in [min, max]. kString with choices: one of them. kStringList: a
 * non-empty list of non-empty, distinct strings. kDoubleList with channels > 0: a list of
 * p+1 values (one per generalized order) or channels * (p+1) (per order and channel,
 * order-major), p = embedding_order (AicParams).
 */
struct ParamSpec
{
  const char* key;          ///< YAML / rosparam / reconfigure name, e.g. "tau"
  ParamType type;           ///< value type
  ParamScope scope;         ///< controller (AicParams: get_aic, set_aic) or node-only (NodeParams: get_node, set_node)
  const char* group;        ///< dynamic_reconfigure group: loops, active_inference, robot, safety, node
  double min;               ///< lower bound (numbers, list elements, integers); NaN for other types
  bool min_exclusive;       ///< true: value > min; false: value >= min
  double max;               ///< upper bound, inclusive; +infinity = none
  const char* unit;         ///< SI unit as in config/*.yaml comments, e.g. "Hz", "-", "SI^2 of each order"
  const char* description;  ///< one sentence, with the thesis equation where there is one
  bool live;                ///< changeable through dynamic_reconfigure (cfg/AIC.cfg)
  int level;                ///< dynamic_reconfigure level bits (1: loop rate, 2: embedding order)
  bool required;            ///< no default: the node refuses to start without it
  int channels;             ///< kDoubleList per generalized order: channels of the per-channel form (3 or 5), else 0
  /// The belief models whose controller reads the value (kAllBeliefModels unless the key belongs to
  /// one model's stages); with another model it has no effect on the command or the beliefs.
  BeliefModelSet models = kAllBeliefModels;
  std::vector<std::string> choices;  ///< kString: allowed values (empty = any)
  /// Live kDoubleList per order: the number of reconfigure slots "<key>_<i>" (kMaxOrders), else 0.
  /// Their defaults are the default list's elements (slotDefault()).
  int reconfigure_slots;
  /// Controller rows: the AicParams member's current value, of the alternative matching `type`
  /// (null for node rows).
  ParamValue (*get_aic)(const AicParams& params);
  /// Controller rows: store a value in the AicParams member; false (member unchanged) if the
  /// value does not fit its C++ type (wrong alternative, or an unknown enumerator name such
  /// as integrator "rk4"). Null for node rows.
  bool (*set_aic)(AicParams& params, const ParamValue& value);
  /// Node rows: as get_aic for the NodeParams member (null for controller rows).
  ParamValue (*get_node)(const NodeParams& params);
  /// Node rows: as set_aic for the NodeParams member (null for controller rows).
  bool (*set_node)(NodeParams& params, const ParamValue& value);
  /// The node's own upper bound when below `max` (the loop rates: `max` is the core's sanity
  /// bound, 1e6 Hz, the node runs at most kMaxLoopRate); +infinity = as `max`.
  double node_max = std::numeric_limits<double>::infinity();

  /// Upper bound in the node (NodeParams::validate(), cfg/AIC.cfg): min(max, node_max).
  double nodeMax() const { return node_max < max ? node_max : max; }
  /// True if the controller of belief model `model` reads the value (`models` holds it).
  bool readBy(BeliefModel model) const { return (models & beliefModelBit(model)) != 0u; }
  /// Number of reconfigure slots (0 unless a live per-order list).
  int slots() const { return reconfigure_slots; }
  /// True for kDouble, kInt, kDoubleList (the range applies).
  bool numeric() const;
  /// The member's value in a NodeParams (controller rows: in its `aic`; include/jackal_aic/params/param_schema.hpp).
  ParamValue get(const NodeParams& params) const;
  /// Store a value in the member of a NodeParams (as set_aic / set_node).
  bool set(NodeParams& params, const ParamValue& value) const;
};

/**
 * \brief Store `value` in *member if it holds the member's type T (a double member also takes
 *        an int). \return false (member unchanged) otherwise. For the rows' set accessors.
 */
template <class T>
bool assignParamValue(T* member, const ParamValue& value)
{
  if (const T* x = std::get_if<T>(&value))
  {
    *member = *x;
    return true;
  }
  if constexpr (std::is_same_v<T, double>)
  {
    if (const int* i = std::get_if<int>(&value))
    {
      *member = *i;
      return true;
    }
  }
  return false;
}

/// The member at the end of a path of member pointers: memberAt<&A::b, &B::c>(a) is a.b.c (const
/// if `root` is).
template <auto First, auto... Rest, class Root>
constexpr auto& memberAt(Root& root)
{
  if constexpr (sizeof...(Rest) == 0)
  {
    return root.*First;
  }
  else
  {
    return memberAt<Rest...>(root.*First);
  }
}

/// The ParamType of a member of C++ type T (double, int, bool, std::string, std::vector<double>,
/// std::vector<std::string>); any other type does not compile.
template <class T>
constexpr ParamType paramTypeOf()
{
  if constexpr (std::is_same_v<T, double>)
  {
    return ParamType::kDouble;
  }
  else if constexpr (std::is_same_v<T, int>)
  {
    return ParamType::kInt;
  }
  else if constexpr (std::is_same_v<T, bool>)
  {
    return ParamType::kBool;
  }
  else if constexpr (std::is_same_v<T, std::string>)
  {
    return ParamType::kString;
  }
  else if constexpr (std::is_same_v<T, std::vector<double>>)
  {
    return ParamType::kDoubleList;
  }
  else
  {
    static_assert(std::is_same_v<T, std::vector<std::string>>, "a parameter member of an unsupported type");
    return ParamType::kStringList;
  }
}

/**
 * \brief One row of the schema, written field by field: each setter names the ParamSpec field it
 *        sets, and the common row is the default (live, reconfigure level 0, optional, not a
 *        per-order list, no choices). The member decides the row's type and scope.
 *
 * A stage parameter is one member of its struct nested in AicParams and one row here, e.g.
 *
 *     ParamRow("active_inference", "reference_delay")
 *         .unit("s")
 *         .atLeast(0.0)
 *         .atMost(kMaxReferenceDelay)
 *         .describe("Reference model: the latency from command to wheel response that the beliefs expect")
 *         .member<&AicParams::reference, &ReferenceModelParams::delay>()
 *
 * member<Path...>() takes the path of member pointers from AicParams to the value (one for a
 * member of AicParams itself); node<Path...>() the same from NodeParams. A row converts to its
 * ParamSpec; the conversion throws std::logic_error naming the key if the row has no member or
 * accessors, no description, or (a number, an integer or a list of numbers) no lower bound.
 */
class ParamRow
{
public:
  /// \param group  dynamic_reconfigure group: loops, active_inference, robot, safety, node, output
  /// \param key    YAML / rosparam / reconfigure name
  ParamRow(const char* group, const char* key);

  /// SI unit as in config/*.yaml comments (default "-").
  ParamRow& unit(const char* unit);
  /// One sentence, with the thesis equation where there is one.
  ParamRow& describe(const char* description);
  /// Lower bound, inclusive: value >= min.
  ParamRow& atLeast(double min);
  /// Lower bound, exclusive: value > min.
  ParamRow& above(double min);
  /// Upper bound, inclusive (default +infinity: none, the value still finite).
  ParamRow& atMost(double max);
  /// The node's own upper bound when below atMost() (ParamSpec::node_max).
  ParamRow& nodeMax(double max);
  /// Not changeable through dynamic_reconfigure (read at start).
  ParamRow& notLive();
  /// dynamic_reconfigure level bits (1: loop rate, 2: embedding order).
  ParamRow& level(int bits);
  /// No default: the node refuses to start without it.
  ParamRow& required();
  /// A list of numbers per generalized order: p+1 values or `channels` per order (order-major);
  /// `slots` reconfigure slots "<key>_<i>" when live.
  ParamRow& perOrder(int channels, int slots);
  /// A string that must be one of `names`.
  ParamRow& choices(std::vector<std::string> names);
  /// Read only by the controllers of these belief models (ParamSpec::models; default: all).
  ParamRow& readBy(BeliefModelSet models);

  /// The AicParams member at the end of the member-pointer path (controller scope).
  template <auto... Path>
  ParamRow& member()
  {
    using T = std::decay_t<decltype(memberAt<Path...>(std::declval<AicParams&>()))>;
    spec_.type = paramTypeOf<T>();
    spec_.scope = ParamScope::kController;
    spec_.get_aic = [](const AicParams& p) -> ParamValue { return memberAt<Path...>(p); };
    spec_.set_aic = [](AicParams& p, const ParamValue& v) { return assignParamValue(&memberAt<Path...>(p), v); };
    return *this;
  }
  /// The NodeParams member at the end of the member-pointer path (node scope).
  template <auto... Path>
  ParamRow& node()
  {
    using T = std::decay_t<decltype(memberAt<Path...>(std::declval<NodeParams&>()))>;
    spec_.type = paramTypeOf<T>();
    spec_.scope = ParamScope::kNode;
    spec_.get_node = [](const NodeParams& p) -> ParamValue { return memberAt<Path...>(p); };
    spec_.set_node = [](NodeParams& p, const ParamValue& v) { return assignParamValue(&memberAt<Path...>(p), v); };
    return *this;
  }
  /// An AicParams member stored as a string (an enumerator's name): its own accessors, type kString.
  ParamRow& accessors(ParamValue (*get)(const AicParams&), bool (*set)(AicParams&, const ParamValue&));
  /// A NodeParams member stored as a string: its own accessors, type kString.
  ParamRow& accessors(ParamValue (*get)(const NodeParams&), bool (*set)(NodeParams&, const ParamValue&));

  /// The row. \throws std::logic_error naming the key if it is incomplete (see the class).
  operator ParamSpec() const;  // NOLINT(google-explicit-constructor): rows are listed as ParamSpecs

private:
  ParamSpec spec_;
};

/// The controller's rows (the keys of AicParams), in the order of `aic_params --yaml`.
const std::vector<ParamSpec>& controllerParamSpecs();

/**
 * \brief Range violations of every controller row in `params`, in table order (see ParamSpec;
 *        the cross rule belief_rate >= action_rate is AicParams::validate()'s). A violation
 *        names the key ("tau"), a list element ("var_mu[2]") or a list size ("var_mu.size()"),
 *        with the value and the allowed range.
 */
std::vector<ParamViolation> checkParamRanges(const AicParams& params);

/**
 * \brief Append the violations of one value of a row (its range, list size for the embedding
 *        order `embedding_order`, choices, string list rules) to *out (the table's rules, for
 *        either scope).
 */
void checkParamValue(const ParamSpec& row, const ParamValue& value, int embedding_order,
                     std::vector<ParamViolation>* out);

/// What a value of a row must be, for messages: "a number", "an integer", "true or false",
/// "a string: euler or exact", "a list of numbers", "a list of strings".
std::string expectedText(const ParamSpec& row);

/// The allowed range of a row as text, e.g. "> 0 and <= 1000000, finite", ">= 0 and finite",
/// "integer in [1, 5]", "euler | exact".
std::string rangeText(const ParamSpec& row);

/// A value printed for messages and docs (numbers with up to 15 significant digits, lists as [a, b]).
std::string formatParamValue(const ParamValue& value);

}  // namespace params
}  // namespace jackal_aic
