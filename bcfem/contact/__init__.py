"""Contact that is not one energy form: self-contact search and gaps, a wall's plate edge."""
