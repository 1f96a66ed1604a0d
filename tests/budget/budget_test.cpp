// Budgets (budget.hpp): one message shape for every loader's refusal, and a
// strict NAME=N parser for command lines that raise them.
#include <gtest/gtest.h>

#include "splatfx/budget.hpp"

using namespace splatfx;

TEST(Budget, AnEstimateOverItsBudgetNamesEstimateBudgetAndField) {
    EXPECT_TRUE(checkBudget("x", 10, "cells", 10, "effectCells"));
    Status s = checkBudget("effects[0].dims: 7x20x5", 700, "cells", 500, "effectCells");
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "effects[0].dims: 7x20x5 needs 700 cells, over the budget of 500 (raise Budgets::effectCells)");
}

TEST(Budget, AssignmentsAreParsedStrictlyAndLeaveTheBudgetsAloneOnError) {
    Budgets b;
    ASSERT_TRUE(setBudget(b, "solverCells=1048576"));
    EXPECT_EQ(b.solverCells, 1048576u);
    ASSERT_TRUE(setBudget(b, "meshElements=5"));
    EXPECT_EQ(b.meshElements, 5u);
    const Budgets before = b;
    for (const char* bad : {"solverCells", "solverCells=", "solverCells=0", "solverCells=-3", "solverCells=12x", "solverCells= 7",
                            "solverCells=99999999999999999999999", "cells=7", "=7", "effectCells=16777217"}) {
        Status s = setBudget(b, bad);
        EXPECT_FALSE(s) << bad;
        EXPECT_EQ(b.solverCells, before.solverCells) << bad;
        EXPECT_EQ(b.effectCells, before.effectCells) << bad;
    }
    Status unknown = setBudget(b, "cells=7");
    EXPECT_NE(unknown.error().find("unknown budget 'cells'"), std::string::npos) << unknown.error();
    for (const std::string& name : budgetNames()) EXPECT_NE(unknown.error().find(name), std::string::npos) << name;
}

TEST(Budget, EveryNamedFieldCanBeSet) {
    for (const std::string& name : budgetNames()) {
        Budgets b;
        EXPECT_TRUE(setBudget(b, name + "=1")) << name;
    }
    EXPECT_EQ(budgetNames().size(), 12u);
}
